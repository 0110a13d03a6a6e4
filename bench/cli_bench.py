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


def start_to_exit_s(argv: Sequence[str]) -> float:
    """Wall seconds from starting ``argv`` to its exit; a failure is an error (a fast
    failure must not pass for a fast start)."""
    started = time.perf_counter()
    done = subprocess.run(argv, capture_output=True, text=True, timeout=60)
    elapsed = time.perf_counter() - started
    if done.returncode != 0:
        raise RuntimeError(f"{' '.join(argv)} exited {done.returncode}: {done.stderr.strip()}")
    return elapsed


@dataclass(frozen=True)
class StartFigures:
    """Medians over the runs, in seconds, and the per-run ratios' medians."""

    python_s: float
    import_zmq_s: float
    help_s: float
    read_s: float
    help_ratio: float
    read_ratio: float


def measure(runs: int = 9) -> StartFigures:
    """``runs`` paired starts of each: python -c pass, then cnc --help; python -c 'import
    zmq', then cnc read (against one service started for the measurement)."""
    python = [sys.executable, "-c", "pass"]
    import_zmq = [sys.executable, "-c", "import zmq"]
    cnc = cnc_argv()
    service = start_service("--clock", "realtime")
    try:
        read = [*cnc, "--endpoint", service.endpoint, "read", READ_NAME]
        for argv in (python, import_zmq, [*cnc, "--help"], read):  # warm the file caches
            start_to_exit_s(argv)
        times: dict[str, list[float]] = {k: [] for k in ("python", "zmq", "help", "read")}
        help_ratios, read_ratios = [], []
        for _ in range(runs):
            times["python"].append(start_to_exit_s(python))
            times["help"].append(start_to_exit_s([*cnc, "--help"]))
            times["zmq"].append(start_to_exit_s(import_zmq))
            times["read"].append(start_to_exit_s(read))
            help_ratios.append(times["help"][-1] / times["python"][-1])
            read_ratios.append(times["read"][-1] / times["python"][-1])
    finally:
        service.stop()
    median = {k: statistics.median(v) for k, v in times.items()}
    return StartFigures(median["python"], median["zmq"], median["help"], median["read"],
                        statistics.median(help_ratios), statistics.median(read_ratios))


def main(runs: int) -> None:
    """Measure and print the cli part's table."""
    fig = measure(max(runs, 5))

    def verdict(seconds: float) -> str:
        return f"< {TARGET_S} s: " + ("met" if seconds < TARGET_S else "NOT met")

    print(f"\ncnc start to exit: median of {max(runs, 5)} runs; ratio: median of the per-run "
          "ratios to python -c pass")
    print(f"\n{'measurement':44} {'ms':>8} {'ratio':>6}  target")
    print(f"{'python -c pass (baseline)':44} {fig.python_s * 1e3:8.1f} {1.0:6.2f}")
    zmq_label = "python -c 'import zmq' (baseline)"
    print(f"{zmq_label:44} {fig.import_zmq_s * 1e3:8.1f} "
          f"{fig.import_zmq_s / fig.python_s:6.2f}")
    print(f"{'cnc --help':44} {fig.help_s * 1e3:8.1f} {fig.help_ratio:6.2f}  "
          f"{verdict(fig.help_s)}")
    print(f"{'cnc read ' + READ_NAME + ' (running service)':44} {fig.read_s * 1e3:8.1f} "
          f"{fig.read_ratio:6.2f}  {verdict(fig.read_s)}")
