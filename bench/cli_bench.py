"""``make bench`` cli part: how long ``cnc`` takes from start to exit.

Each figure is a whole process, as a shell loop runs it: ``cnc --help``, and ``cnc read``
of one object against a running service (realtime clock, in a second process). The
baselines, measured in the same run right before each ``cnc`` figure, are the bare
interpreter (``python -c pass``) and ``python -c 'import zmq'`` (the least a client that
talks to the service must load). Figures are medians of ``runs`` starts; the ratio is the
median of the per-run ratios to ``python -c pass``. Target (issue 29): both under 0.25 s
on a 2-core machine.

    python -m bench --part cli [--runs N]
"""

from __future__ import annotations

import os
import statistics
import subprocess
import sys
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from tests.support.service import start_service

TARGET_S = 0.25  # issue 29: cnc --help and a read, start to exit
READ_NAME = "cnc_cycle_time_r"  # an object every machine has


def cnc_argv() -> list[str]:
    """How a user starts ``cnc``: the installed script beside this interpreter, else its
    entry point through the interpreter (the same code, one file less to open)."""
    script = Path(sys.executable).with_name("cnc")
    if script.is_file():
        return [str(script)]
    return [sys.executable, "-c", "from cnc_objects.clients.cli import main; main()"]


@dataclass(frozen=True)
class Start:
    """One start of a process: wall seconds to its exit, and the CPU seconds it used (user
    + system; on a loaded machine the wall time is mostly waiting for a core)."""

    wall_s: float
    cpu_s: float


def start_to_exit(argv: Sequence[str], env: dict[str, str] | None = None) -> Start:
    """Start ``argv`` and wait for its exit; a failure is an error (a fast failure must
    not pass for a fast start)."""
    started = time.perf_counter()
    process = subprocess.Popen(argv, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, env=env)
    _, status, usage = os.wait4(process.pid, 0)
    elapsed = time.perf_counter() - started
    process.returncode = os.waitstatus_to_exitcode(status)
    stderr = process.stderr.read().decode(errors="replace") if process.stderr else ""
    if process.stderr:
        process.stderr.close()
    if process.returncode != 0:
        raise RuntimeError(f"{' '.join(argv)} exited {process.returncode}: {stderr.strip()}")
    return Start(elapsed, usage.ru_utime + usage.ru_stime)


@dataclass(frozen=True)
class Figure:
    """One measurement over the runs: medians of wall and CPU seconds, and the median of
    the per-run ratios of the wall time to ``python -c pass``'s of the same run."""

    wall_s: float
    cpu_s: float
    ratio: float


MEASURED = ("python", "zmq", "help", "read")  # the keys of measure()'s figures


def measure(runs: int = 9) -> dict[str, Figure]:
    """``runs`` rounds of: python -c pass, cnc --help, python -c 'import zmq', cnc read
    (against one service started for the measurement)."""
    cnc = cnc_argv()
    service = start_service("--clock", "realtime")
    try:
        argvs = {"python": [sys.executable, "-c", "pass"],
                 "zmq": [sys.executable, "-c", "import zmq"],
                 "help": [*cnc, "--help"],
                 "read": [*cnc, "--endpoint", service.endpoint, "read", READ_NAME]}
        # Warm the file caches, and write the byte code as an installed package has it: a
        # start under PYTHONDONTWRITEBYTECODE=1 (as in some shells and containers) would
        # otherwise compile every module of the client from source, every time.
        compiling = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
        for argv in argvs.values():
            start_to_exit(argv, compiling)
        starts: dict[str, list[Start]] = {k: [] for k in MEASURED}
        for _ in range(runs):
            for key in MEASURED:
                starts[key].append(start_to_exit(argvs[key]))
    finally:
        service.stop()
    baseline = [s.wall_s for s in starts["python"]]
    return {key: Figure(statistics.median(s.wall_s for s in measured),
                        statistics.median(s.cpu_s for s in measured),
                        statistics.median(s.wall_s / b for s, b in zip(measured, baseline)))
            for key, measured in starts.items()}


LABELS = {
    "python": "python -c pass (baseline)",
    "zmq": "python -c 'import zmq' (baseline)",
    "help": "cnc --help",
    "read": f"cnc read {READ_NAME} (running service)",
}


def main(runs: int) -> None:
    """Measure and print the cli part's table."""
    runs = max(runs, 5)
    figures = measure(runs)
    print(f"\ncnc start to exit: median of {runs} runs; ratio: median of the per-run ratios "
          "of the wall time to python -c pass; CPU: user + system of the process")
    print(f"\n{'measurement':44} {'wall ms':>8} {'CPU ms':>7} {'ratio':>6}  target")
    for key in MEASURED:
        fig = figures[key]
        target = ""
        if key in ("help", "read"):
            target = f"< {TARGET_S} s: " + ("met" if fig.wall_s < TARGET_S else "NOT met")
        print(f"{LABELS[key]:44} {fig.wall_s * 1e3:8.1f} {fig.cpu_s * 1e3:7.1f} "
              f"{fig.ratio:6.2f}  {target}")
