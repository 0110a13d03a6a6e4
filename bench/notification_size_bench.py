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
read could take seconds, or get no reply within ``READ_TIMEOUT_S``, which ends the
scenario and counts as that long), and whether the service stopped on SIGINT. For the
"before" figures, run it with ``service/`` of an older commit: it needs only the wire.
"""

from __future__ import annotations

import statistics
import sys
import time
from dataclasses import dataclass

from cnc_objects.testing import ServiceProcess, start_service
from tests.support.large_notifications import (
    ATTACK_BYTES,
    ATTACKS,
    DEFAULTS_LARGEST,
    REALTIME,
    Monitor,
    monitor,
    read_latencies,
)
from tests.support.notification_load import READ_TIMEOUT_S, p99

BUDGET_S = 30.0  # wall time one scenario reads for at most
CHUNK = 10  # reads per connection of the reader


@dataclass(frozen=True)
class Scenario:
    """One scenario's outcome: read latencies (s; a read with no reply counts as
    ``READ_TIMEOUT_S`` and ends the scenario), subscriptions taken, and whether the
    service stopped by itself on SIGINT."""

    latencies_s: list[float]
    taken: int
    timed_out: bool  # a read or a subscription got no reply
    stopped: bool


def reads_within(service: ServiceProcess, front_end: str,
                 count: int) -> tuple[list[float], bool]:
    """Up to ``count`` reads, in chunks of ``CHUNK``, for at most ``BUDGET_S``; and
    whether one got no reply within ``READ_TIMEOUT_S``."""
    latencies: list[float] = []
    deadline = time.monotonic() + BUDGET_S
    while len(latencies) < count and time.monotonic() < deadline:
        try:
            latencies += read_latencies(service, front_end, CHUNK)
        except (TimeoutError, AssertionError):
            return [*latencies, READ_TIMEOUT_S], True
    return latencies, False


def measure(front_end: str, reads: int, subscriptions: tuple[int, int]) -> Scenario:
    """A fresh realtime service; ``subscriptions`` (count, bytes) on change by one client,
    then ``reads`` reads of another."""
    count, length = subscriptions
    service = start_service(*REALTIME, ads=front_end == "ads")
    try:
        with monitor(service, front_end) as attacker:
            taken, timed_out = subscribe(attacker, count, length)
            latencies, read_timed_out = reads_within(service, front_end, reads)
    finally:
        code = service.stop()  # killed when it does not stop within 10 s
    return Scenario(latencies, taken, timed_out or read_timed_out, code == 0)


def subscribe(attacker: Monitor, count: int, length: int) -> tuple[int, bool]:
    """``count`` subscriptions of ``length`` bytes: how many were taken, and whether one
    got no reply (the rest are not sent then)."""
    taken = 0
    for _ in range(count):
        try:
            taken += attacker.subscribe(length)[0] == 0
        except (TimeoutError, AssertionError):
            return taken, True
    return taken, False


def main(runs: int, reads: int) -> None:
    """Each scenario on each front end ``runs`` times; print the medians."""
    for front_end in ("ads", "zmq"):
        name = {"zmq": "ZeroMQ", "ads": "ADS"}[front_end]
        scenarios = {
            "idle": (0, 0),
            "attack": (ATTACKS, ATTACK_BYTES[front_end]),
            "defaults": DEFAULTS_LARGEST,
        }
        print(f"\n{name}: another client's reads beside on-change notifications of the PLC "
              f"memory area (851/0x4020/0x10100); realtime clock, median of {runs} runs "
              f"of up to {reads} reads ({BUDGET_S:.0f} s at most)")
        print(f"{'scenario':34} {'taken':>7} {'reads':>6} {'p50 ms':>9} {'p99 ms':>9} "
              f"{'max ms':>9}  notes")
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
            notes = []
            if any(r.timed_out for r in results):
                notes.append(f"a request had no reply in {READ_TIMEOUT_S:.0f} s")
            if not all(r.stopped for r in results):
                notes.append("service killed: no stop within 10 s of SIGINT")
            print(f"{what:34} {f'{results[0].taken}/{count}':>7} "
                  f"{med(len(r.latencies_s) for r in results):6.0f} "
                  f"{med(med(r.latencies_s) for r in results) * 1e3:9.2f} "
                  f"{med(p99(r.latencies_s) for r in results) * 1e3:9.2f} "
                  f"{med(max(r.latencies_s) for r in results) * 1e3:9.1f}  "
                  f"{'; '.join(notes)}")
