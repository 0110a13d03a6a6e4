"""Another client's reads while one client uses up the notification limit (``make
bench``, part ``fairness``; issue 25).

A realtime service (1 ms cycle) serves ``notifications_total`` cyclic notifications (20
connections of 1 000, every 1 ms, over five objects; every sample read by a client
process of its own, ``tests/support/cyclic_subscribers.py``) while another client reads
one object at a time; once over ZeroMQ, once over ADS (subscriptions and reads). Printed:
that client's read latency p50 / p99 / max, idle and
loaded, and the samples per second the subscribers got. Target (issue 25): p99 under
load below 10 ms. Then another client's reads beside large notifications
(``notification_size_bench``, issue 35).
"""

from __future__ import annotations

import statistics
import sys
import time
from dataclasses import dataclass

from cnc_objects.service.limits import LimitsConfig
from tests.support.notification_load import (
    ads_read_latencies_s,
    ads_target,
    notification_load,
    p99,
    read_latencies_s,
)
from tests.support.service import serving

from . import notification_size_bench

TARGET_P99_S = 0.010
LIMITS = LimitsConfig()


@dataclass(frozen=True)
class Fairness:
    """One run: read latencies idle and loaded (s), samples per second meanwhile."""

    idle_s: list[float]
    loaded_s: list[float]
    samples_per_s: float


def measure_once(reads: int, front_end: str) -> Fairness:
    """A fresh realtime service, ``reads`` reads idle, then ``reads`` under the load,
    subscriptions and reads on ``front_end`` (``zmq`` or ``ads``)."""
    sockets = LIMITS.notifications_total // LIMITS.notifications_per_client
    with serving("--clock", "realtime", ads=front_end == "ads") as service:
        if front_end == "ads":
            address, net_id = service.ads_address, service.ams_net_id
            assert address is not None and net_id is not None
            target = ads_target(address, net_id)

            def timed() -> list[float]:
                return ads_read_latencies_s(address, net_id, reads)
        else:
            target = service.endpoint

            def timed() -> list[float]:
                return read_latencies_s(service.endpoint, reads)
        idle = timed()
        with notification_load(target, sockets, LIMITS.notifications_per_client) as samples:
            started = time.monotonic()
            loaded = timed()
            elapsed_s = time.monotonic() - started
    return Fairness(idle, loaded, (samples[0] if samples else 0) / elapsed_s)


def main(runs: int, reads: int) -> None:
    """Measure ``runs`` times on each front end and print the medians; then reads beside
    large notifications (``notification_size_bench``, issue 35)."""
    for front_end in ("zmq", "ads"):
        report(front_end, runs, reads)
    notification_size_bench.main(runs, reads)


def report(front_end: str, runs: int, reads: int) -> None:
    """Measure ``runs`` times on ``front_end`` and print the medians."""
    results = []
    for run in range(runs):
        results.append(measure_once(reads, front_end))
        r = results[-1]
        print(f"fairness {front_end} run {run + 1}/{runs}: loaded p99 "
              f"{p99(r.loaded_s) * 1e3:.2f} ms, {r.samples_per_s:.0f} samples/s",
              file=sys.stderr)
    med = statistics.median
    loaded_p99 = med(p99(r.loaded_s) for r in results)
    name = {"zmq": "ZeroMQ", "ads": "ADS"}[front_end]
    print(f"\n{name}: another client's reads while {LIMITS.notifications_total} cyclic "
          f"notifications (1 ms, {name}) are served; realtime clock, median of {runs} runs "
          f"of {reads} reads")
    print(f"{'measurement':44} {'value':>10}  target")
    print(f"{'reads idle p50 / p99 (ms)':44} "
          f"{med(med(r.idle_s) for r in results) * 1e3:5.2f} / "
          f"{med(p99(r.idle_s) for r in results) * 1e3:.2f}")
    print(f"{'reads loaded p50 (ms)':44} {med(med(r.loaded_s) for r in results) * 1e3:10.2f}")
    print(f"{'reads loaded p99 (ms)':44} {loaded_p99 * 1e3:10.2f}  < 10: "
          f"{'met' if loaded_p99 < TARGET_P99_S else 'NOT met'}")
    print(f"{'reads loaded max (ms)':44} {med(max(r.loaded_s) for r in results) * 1e3:10.1f}")
    print(f"{'samples sent per s':44} {med(r.samples_per_s for r in results):10.0f}")
