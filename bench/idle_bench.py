"""``make bench`` idle part: what an idle service costs (issue 36 point 10).

Two figures of a machine at rest (no program, no jog, no spindle ramp, no client):

* the kernel's idle cycle, in process: microseconds per cycle of ``IDLE_CYCLES`` cycles
  run back to back by the step clock (``StepCycles``), resting (the default) and with
  every cycle's whole work (``rest_when_idle=False``, the reference it must equal);
* the whole ``cnc-service`` on the realtime clock (1 ms cycle, its defaults), no client:
  CPU % of one core and resident memory over ``seconds`` (/proc/<pid>/stat), against a
  bare Python loop that sleeps to a 1 ms deadline in the same run (the least any cycle
  thread in Python costs: a wake-up a millisecond).

    python -m bench --part idle [--runs N] [--idle-s S]
"""

from __future__ import annotations

import os
import statistics
import subprocess
import sys
import threading
import time

from cnc_objects.service.config import build_config
from cnc_objects.service.kernel.commands import Refusal
from cnc_objects.service.kernel.kernel import Kernel
from cnc_objects.service.kernel.step_clock import StepClock, StepCycles
from tests.support.resources import cpu_s, rss_kib
from tests.support.service import start_service

IDLE_CYCLES = 20_000  # cycles per in-process measurement
SETTLE_S = 2.0  # the service's start-up (imports, catalog, first collections) ends first
# The floor: a thread that sleeps to each 1 ms deadline and does nothing else.
_SLEEP_LOOP = """
import ctypes, sys, time
try:
    ctypes.CDLL(None).prctl(29, 1, 0, 0, 0)  # PR_SET_TIMERSLACK 1 ns, as the cycle thread
except (OSError, AttributeError):
    pass
deadline, end = time.perf_counter(), time.perf_counter() + float(sys.argv[1])
while deadline < end:
    deadline += 0.001
    remaining = deadline - time.perf_counter()
    if remaining > 0:
        time.sleep(remaining)
"""


def cycle_us(rest_when_idle: bool, cycles: int = IDLE_CYCLES) -> float:
    """Microseconds per cycle of an idle kernel stepped ``cycles`` cycles at once."""
    config = build_config()
    kernel = Kernel(config, StepClock(config.cycle_ms / 1000.0, max_cycles=cycles),
                    rest_when_idle=rest_when_idle)
    kernel.start()
    try:
        _step(kernel, 100)  # the first cycles settle (and may not rest)
        started = time.perf_counter()
        _step(kernel, cycles)
        return (time.perf_counter() - started) / cycles * 1e6
    finally:
        kernel.close()


def _step(kernel: Kernel, cycles: int) -> None:
    done = threading.Event()
    result: list[Refusal | None] = []

    def finished(refusal: Refusal | None) -> None:
        result.append(refusal)
        done.set()

    kernel.submit(StepCycles(cycles), finished)
    if not done.wait(120.0) or result[0] is not None:
        raise RuntimeError(f"the step of {cycles} cycles failed: {result}")


def service_idle(seconds: float) -> tuple[float, float]:
    """(CPU % of one core, resident MB) of an idle realtime ``cnc-service``."""
    service = start_service("--clock", "realtime")
    try:
        pid = service.process.pid
        time.sleep(SETTLE_S)
        used, started = cpu_s(pid), time.monotonic()
        time.sleep(seconds)
        percent = 100.0 * (cpu_s(pid) - used) / (time.monotonic() - started)
        return percent, rss_kib(pid) / 1024.0
    finally:
        service.stop()


def sleep_loop(seconds: float) -> float:
    """CPU % of one core of a bare 1 ms sleep loop in its own interpreter (its start
    included: a few tens of ms over ``seconds``)."""
    process = subprocess.Popen([sys.executable, "-c", _SLEEP_LOOP, str(seconds)])
    _, status, usage = os.wait4(process.pid, 0)
    process.returncode = os.waitstatus_to_exitcode(status)
    return 100.0 * (usage.ru_utime + usage.ru_stime) / seconds


def main(runs: int, seconds: float) -> None:
    """Measure and print the idle part's table."""
    runs = max(1, runs)
    resting = [cycle_us(True) for _ in range(runs)]
    whole = [cycle_us(False) for _ in range(runs)]
    services = [service_idle(seconds) for _ in range(runs)]
    floors = [sleep_loop(min(seconds, 10.0)) for _ in range(runs)]
    print(f"\nidle machine: median of {runs} runs")
    print(f"{'measurement':52} {'figure':>12}")
    print(f"{'kernel idle cycle, resting (in process)':52} {statistics.median(resting):9.1f} us")
    print(f"{'kernel idle cycle, whole work (reference)':52} {statistics.median(whole):9.1f} us")
    print(f"{f'cnc-service realtime, no client: CPU over {seconds:g} s':52} "
          f"{statistics.median(s[0] for s in services):9.1f} %")
    print(f"{'cnc-service realtime, no client: resident memory':52} "
          f"{statistics.median(s[1] for s in services):9.0f} MB")
    print(f"{'bare 1 ms sleep loop in Python (baseline): CPU':52} "
          f"{statistics.median(floors):9.1f} %")
