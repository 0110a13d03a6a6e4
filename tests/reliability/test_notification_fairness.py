"""Fairness: with the notification limit used up by one client, another client's plain
reads are still answered at once (issue 25).

One client process (``tests/support/cyclic_subscribers.py``) holds every notification
the service takes (``notifications_total``, 20 000: 20 connections of 1 000 cyclic
notifications each, every 1 ms, over five objects) and reads every sample; meanwhile
another client reads one object at a time. Both over ZeroMQ, then both over ADS. Before
the hub sampled in slices, each pass
over the 20 000 subscriptions held the event loop for 170-480 ms and the reads waited
behind it. The bench (``make bench``, part ``fairness``) reports the real figure on the
realtime clock; this test asserts a bound that a loaded 2-core machine keeps.
"""

from __future__ import annotations

import statistics

import pytest

from cnc_objects.service.limits import LimitsConfig
from cnc_objects.testing import serving
from tests.reliability import figures
from tests.reliability.scale import Scale
from tests.support.notification_load import (
    ads_read_latencies_s,
    ads_target,
    notification_load,
    p99,
    read_latencies_s,
)

NODE = "tests/reliability/test_notification_fairness.py"
LIMITS = LimitsConfig()
SOCKETS = LIMITS.notifications_total // LIMITS.notifications_per_client  # 20
#: The bound asserted here; the target (10 ms) is the bench's, on an unshared machine.
P99_BOUND_S = 0.050


@pytest.mark.parametrize("front_end", ["zmq", "ads"])
def test_reads_stay_fast_while_the_notification_limit_is_used_up(
    run_scale: Scale, front_end: str
) -> None:
    """Subscriptions and the other client's reads on ``front_end``."""
    reads = run_scale.fairness_reads
    with serving(ads=front_end == "ads") as service:
        if front_end == "ads":
            address, net_id = service.ads_address, service.ams_net_id
            assert address is not None and net_id is not None
            with notification_load(ads_target(address, net_id), SOCKETS,
                                   LIMITS.notifications_per_client) as samples:
                latencies_s = ads_read_latencies_s(address, net_id, reads)
        else:
            with notification_load(service.endpoint, SOCKETS,
                                   LIMITS.notifications_per_client) as samples:
                latencies_s = read_latencies_s(service.endpoint, reads)
    assert samples and samples[0] > 0, "the subscribers received no samples"
    worst_s = p99(latencies_s)
    figures.record(
        f"{front_end}: reads of another client under {LIMITS.notifications_total} cyclic "
        "notifications",
        f"p50 {statistics.median(latencies_s) * 1e3:.2f} ms, p99 {worst_s * 1e3:.2f} ms, "
        f"max {max(latencies_s) * 1e3:.1f} ms; {samples[0]} samples sent meanwhile", NODE)
    assert worst_s < P99_BOUND_S, (
        f"p99 of the reads {worst_s * 1e3:.1f} ms (bound {P99_BOUND_S * 1e3:.0f} ms)")
