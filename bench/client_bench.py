"""``AsyncClient`` batching against the raw pipelined echo (``make bench``, part ``client``;
issue 30).

In each run, back to back: the raw pipelined pyzmq echo (64 frames in flight, the
baseline of the dispatch part), then ``AsyncClient`` against the service (virtual clock:
no cycle deadlines to keep) in bursts (``asyncio.gather`` of 64 reads) and in a sliding
window (64 coroutines), each batched (the default) and with ``batch=False``.

Two figures per measurement. Reads per second of wall time, and its ratio to the raw
echo of the same run: the target (>= 0.8), but on a machine shared with other work it
swings with the load. And the CPU time per read, of the client process (its ZeroMQ I/O
thread included) and of the serving process (the service, or the echo), from the
kernel's accounting: what a read costs whatever else runs. On two cores, one per
process, the slower of the two bounds the rate: ``cpu-bound reads/s`` is
``1 / max(client, server)`` per read, the rate an otherwise idle machine would reach.
"""

from __future__ import annotations

import multiprocessing as mp
import os
import statistics
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass

from tests.support.service import start_service

from .__main__ import IN_FLIGHT, client_bursts, client_in_flight, raw_pipelined
from .raw_echo import serve_echo

_TICK_S = 1.0 / os.sysconf("SC_CLK_TCK")


def _cpu_s(pid: int) -> float:
    """User + system CPU seconds of process ``pid`` (all its threads)."""
    with open(f"/proc/{pid}/stat") as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) * _TICK_S


@dataclass(frozen=True)
class Cost:
    """One measurement: wall rate and CPU microseconds per read on each side."""

    reads_s: float
    client_us: float
    server_us: float

    @property
    def cpu_bound_reads_s(self) -> float:
        return 1e6 / max(self.client_us, self.server_us)


def _measure(run: Callable[[], object], count: int, server_pid: int) -> Cost:
    client0, server0, wall0 = time.process_time(), _cpu_s(server_pid), time.perf_counter()
    run()
    wall = time.perf_counter() - wall0
    client, server = time.process_time() - client0, _cpu_s(server_pid) - server0
    return Cost(count / wall, client / count * 1e6, server / count * 1e6)


MODES: dict[str, Callable[[str, int], object]] = {
    "bursts": lambda e, n: client_bursts(e, n, batch=True),
    "bursts, batch=False": lambda e, n: client_bursts(e, n, batch=False),
    "window": lambda e, n: client_in_flight(e, n, batch=True),
    "window, batch=False": lambda e, n: client_in_flight(e, n, batch=False),
}


def main(runs: int, count: int) -> None:
    """Measure ``runs`` times and print medians; ratios are per run, then the median."""
    ctx = mp.get_context("spawn")
    port_queue = ctx.Queue()
    ready = ctx.Event()  # kept: the child unpickles it after start() returns
    echo = ctx.Process(target=serve_echo, args=(port_queue, ready), daemon=True)
    echo.start()
    echo_endpoint = port_queue.get(timeout=20)
    service = start_service("--clock", "virtual")
    raw: list[Cost] = []
    costs: dict[str, list[Cost]] = {m: [] for m in MODES}
    ratios: dict[str, list[float]] = {m: [] for m in MODES}
    try:
        for run in range(runs):
            base = _measure(lambda: raw_pipelined(echo_endpoint, count), count, echo.pid)
            raw.append(base)
            for mode, read in MODES.items():
                cost = _measure(lambda read=read: read(service.endpoint, count),  # type: ignore[misc]
                                count, service.process.pid)
                costs[mode].append(cost)
                ratios[mode].append(cost.reads_s / base.reads_s)
            print(f"client run {run + 1}/{runs}: raw {base.reads_s:.0f}/s; " + ", ".join(
                f"{m} {ratios[m][-1]:.2f}" for m in MODES), file=sys.stderr)
    finally:
        service.stop()
        echo.terminate()
    med = statistics.median
    print(f"\nAsyncClient against the raw pipelined echo ({IN_FLIGHT} in flight), median of "
          f"{runs} runs of {count} reads; wall ratio: median of the per-run ratios")
    print(f"{'measurement':30} {'reads/s':>9} {'ratio':>6} {'client us':>10} {'server us':>10} "
          f"{'cpu-bound/s':>12} {'ratio':>6}  target")
    raw_bound = med(c.cpu_bound_reads_s for c in raw)
    print(f"{'raw echo, 64 in flight':30} {med(c.reads_s for c in raw):9.0f} {1:6.2f} "
          f"{med(c.client_us for c in raw):10.1f} {med(c.server_us for c in raw):10.1f} "
          f"{raw_bound:12.0f} {1:6.2f}")
    for mode in MODES:
        got = costs[mode]
        ratio = med(ratios[mode])
        bound = med(c.cpu_bound_reads_s for c in got)
        verdict = ("" if "False" in mode else
                   f">= 0.8: {'met' if ratio >= 0.8 else 'NOT met'} (wall)")
        print(f"{mode:30} {med(c.reads_s for c in got):9.0f} {ratio:6.2f} "
              f"{med(c.client_us for c in got):10.1f} {med(c.server_us for c in got):10.1f} "
              f"{bound:12.0f} {bound / raw_bound:6.2f}  {verdict}")
