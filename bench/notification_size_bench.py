"""Another client's reads beside large notifications (``make bench``, part ``fairness``;
issue 35).

A realtime service (1 ms cycle, default ``[limits]``); one client (the monitor, a
loopback peer) subscribes on change to a range of the PLC memory area from gpCh (851 /
0x4020 / 0x10100), another client reads one object at a time on the same front end.
Three scenarios per front end:

- ``idle``: no subscription;
- ``attack``: 20 notifications of 60 000 bytes (ADS) or 460 032 bytes (ZeroMQ), the
  issue's attack (refused 0x717 by ``notification_max_bytes`` since issue 35);
- ``defaults``: the largest the default limits take, 8 notifications of 8 192 bytes
  (``notification_bytes_per_client`` / ``notification_max_bytes``; gpCh whole).

Printed: the reads' p50 / p99 / max, how many subscriptions the service took, and how
many reads were done (each scenario reads for at most ``BUDGET_S``: before issue 35 a
read could take seconds). Run it on an older commit for the "before" figures: it needs
only the service's wire.
"""

from __future__ import annotations

import statistics
import sys
import time
from dataclasses import dataclass

from cnc_objects.testing import ServiceProcess, serving
from tests.support.large_notifications import (
    ATTACK_BYTES,
    ATTACKS,
    REALTIME,
    monitor,
    read_latencies,
)
from tests.support.notification_load import p99

BUDGET_S = 30.0  # wall time one scenario reads for at most
CHUNK = 50  # reads per connection of the reader
#: The largest the default limits take: 64 KiB per client in notifications of 8 KiB.
DEFAULTS = (8, 8192)


@dataclass(frozen=True)
class Scenario:
    """One scenario's outcome: read latencies (s) and subscriptions taken / asked."""

    latencies_s: list[float]
    taken: int
    asked: int


def reads_within(service: ServiceProcess, front_end: str, count: int) -> list[float]:
    """Up to ``count`` reads, in chunks of ``CHUNK``, for at most ``BUDGET_S``."""
    latencies: list[float] = []
    deadline = time.monotonic() + BUDGET_S
    while len(latencies) < count and time.monotonic() < deadline:
        latencies += read_latencies(service, front_end, CHUNK)
    return latencies


def measure(front_end: str, reads: int, subscriptions: tuple[int, int]) -> Scenario:
    """A fresh realtime service; ``subscriptions`` (count, bytes) on change by one client,
    then ``reads`` reads of another."""
    count, length = subscriptions
    with serving(*REALTIME, ads=front_end == "ads") as service, \
            monitor(service, front_end) as attacker:
        taken = sum(attacker.subscribe(length)[0] == 0 for _ in range(count))
        latencies = reads_within(service, front_end, reads)
    return Scenario(latencies, taken, count)


def main(runs: int, reads: int) -> None:
    """Each scenario on each front end ``runs`` times; print the medians."""
    for front_end in ("ads", "zmq"):
        name = {"zmq": "ZeroMQ", "ads": "ADS"}[front_end]
        scenarios = {
            "idle": (0, 0),
            "attack": (ATTACKS, ATTACK_BYTES[front_end]),
            "defaults": DEFAULTS,
        }
        print(f"\n{name}: another client's reads beside on-change notifications of the PLC "
              f"memory area (851/0x4020/0x10100); realtime clock, median of {runs} runs "
              f"of up to {reads} reads ({BUDGET_S:.0f} s at most)")
        print(f"{'scenario':34} {'taken':>7} {'reads':>6} {'p50 ms':>9} {'p99 ms':>9} "
              f"{'max ms':>9}")
        for label, subscriptions in scenarios.items():
            results = []
            for run in range(runs):
                results.append(measure(front_end, reads, subscriptions))
                r = results[-1]
                print(f"size {front_end} {label} run {run + 1}/{runs}: p99 "
                      f"{p99(r.latencies_s) * 1e3:.2f} ms", file=sys.stderr)
            med = statistics.median
            count, length = subscriptions
            what = f"{label} ({count} x {length} B)" if count else label
            print(f"{what:34} {f'{results[0].taken}/{count}':>7} "
                  f"{med(len(r.latencies_s) for r in results):6.0f} "
                  f"{med(med(r.latencies_s) for r in results) * 1e3:9.2f} "
                  f"{med(p99(r.latencies_s) for r in results) * 1e3:9.2f} "
                  f"{med(max(r.latencies_s) for r in results) * 1e3:9.1f}")
