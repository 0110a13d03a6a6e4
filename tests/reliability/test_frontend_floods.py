"""Partial frames and connection floods: what clients can make the service hold is bounded
(issue 25, hole 4), and everyone else is served meanwhile.

Each flood comes from raw TCP sockets (``floods``), as an attacker sends it: ADS frames
that announce 1 MiB and stop 100 bytes short, ZeroMQ frames that announce 2 MB and stop
100 bytes short, connections beyond the cap, frames that never complete. The service's
resident memory (``VmRSS``) is measured before and while the flood holds its sockets
open; a client connected before the flood must be answered throughout, and what the
service closed it must have logged.
"""

from __future__ import annotations

import time
from pathlib import Path

from cnc_objects.protocol.constants import CncPort
from cnc_objects.protocol.frames import ReadRequest
from cnc_objects.service.limits import LimitsConfig
from cnc_objects.testing import serving
from tests.limits.wire import limited_service
from tests.reliability import figures
from tests.reliability.floods import (
    AdsProbe,
    Flood,
    ads_half_frame,
    wait_until,
    zmtp_greeting,
    zmtp_half_frame,
)
from tests.reliability.health import TICK_ADDRESS, RawConnection
from tests.reliability.scale import Scale
from tests.support.resources import rss_kib

NODE = "tests/reliability/test_frontend_floods.py"
DEFAULTS = LimitsConfig()
ADS_FRAME_BYTES = 1 << 20  # the largest AMS/TCP frame ([ads] max_frame_bytes)
ZMQ_FRAME_BYTES = 2_000_000  # under the ZeroMQ hard cap (2 x max_frame_bytes)
MISSING_BYTES = 100
#: What the allocator, the libraries and one read per connection may add on top of the
#: limits (far below the 200-300 MiB a flood held before the limits).
RSS_SLACK_KIB = 24 * 1024
CLOSE_TIMEOUT_S = 60.0  # a flood's connections closed, on a loaded 2-core machine
SMALL_TIMEOUT_S = 1.0  # frame_timeout_s of the timeout tests
SMALL_CAP = 8  # connections_per_front_end of the cap tests
COM = CncPort.COM


def _zmq_address(endpoint: str) -> tuple[str, int]:
    host, port = endpoint.removeprefix("tcp://").rsplit(":", 1)
    return host.strip("[]"), int(port)


def test_an_ads_partial_frame_flood_holds_bounded_memory(run_scale: Scale) -> None:
    """Connections that each send 1 MiB - 100 bytes of a 1 MiB frame: those that would
    take the incomplete frames of all connections over ``receive_buffer_bytes_total``
    (or beyond ``connections_per_front_end``) are closed; RSS grows by at most the
    budget; a client connected before is answered."""
    count = run_scale.flood_ads
    with serving(ads=True) as service:
        assert service.ads_address is not None and service.ams_net_id is not None
        probe = AdsProbe(service.ads_address, service.ams_net_id)
        assert probe.read_device_info() == 0
        before_kib = rss_kib(service.process.pid)
        fits = min(DEFAULTS.connections_per_front_end,
                   DEFAULTS.receive_buffer_bytes_total // ADS_FRAME_BYTES)
        with Flood(service.ads_address, count,
                   ads_half_frame(ADS_FRAME_BYTES, MISSING_BYTES)) as flood:
            closed = flood.wait_closed(count - fits, CLOSE_TIMEOUT_S)
            during_kib = rss_kib(service.process.pid)
            assert probe.read_device_info() == 0
        probe.close()
        service.wait_for_log("receive_buffer_bytes_total")
    growth_kib = during_kib - before_kib
    figures.record(f"ADS flood: {count} connections x (1 MiB - 100 B) half frames",
                   f"RSS {before_kib >> 10} -> {during_kib >> 10} MiB, {closed} closed", NODE)
    assert closed >= count - fits, f"only {closed} of {count} flooding connections closed"
    bound_kib = (DEFAULTS.receive_buffer_bytes_total >> 10) + RSS_SLACK_KIB
    assert growth_kib < bound_kib, f"RSS grew by {growth_kib >> 10} MiB (bound {bound_kib >> 10})"


def test_a_zeromq_partial_frame_flood_holds_bounded_memory(run_scale: Scale) -> None:
    """Connections that each send 2 MB - 100 bytes of a 2 MB frame: those beyond
    ``connections_per_front_end`` are shut down at once; RSS grows by at most the cap
    times the frame hard cap; a client connected before is answered."""
    count = run_scale.flood_zmq
    with serving() as service:
        with RawConnection(service.endpoint) as probe:
            assert probe.call(ReadRequest, *TICK_ADDRESS, 4)[2] == 0
            before_kib = rss_kib(service.process.pid)
            admitted = DEFAULTS.connections_per_front_end - 1  # the probe holds one
            with Flood(_zmq_address(service.endpoint), count,
                       zmtp_half_frame(ZMQ_FRAME_BYTES, MISSING_BYTES)) as flood:
                closed = flood.wait_closed(count - admitted, CLOSE_TIMEOUT_S)
                during_kib = rss_kib(service.process.pid)
                assert probe.call(ReadRequest, *TICK_ADDRESS, 4)[2] == 0
        service.wait_for_log("connections_per_front_end")
    growth_kib = during_kib - before_kib
    figures.record(f"ZeroMQ flood: {count} connections x (2 MB - 100 B) half frames",
                   f"RSS {before_kib >> 10} -> {during_kib >> 10} MiB, {closed} closed", NODE)
    assert closed >= count - admitted, f"only {closed} of {count} flooding connections closed"
    bound_kib = (DEFAULTS.zmq_receive_bound_bytes >> 10) + RSS_SLACK_KIB
    assert growth_kib < bound_kib, f"RSS grew by {growth_kib >> 10} MiB (bound {bound_kib >> 10})"


def test_a_frame_that_never_completes_is_closed_after_the_timeout(tmp_path: Path) -> None:
    """Half a frame, then nothing: both front ends close that connection once
    ``frame_timeout_s`` has passed (ZeroMQ within twice it: libzmq's heartbeat), and
    serve the others meanwhile."""
    with limited_service(tmp_path, ads=True, frame_timeout_s=SMALL_TIMEOUT_S) as service:
        assert service.ads_address is not None and service.ams_net_id is not None
        with Flood(service.ads_address, 1, ads_half_frame(4096, 1000)) as ads, \
                Flood(_zmq_address(service.endpoint), 1, zmtp_half_frame(4096, 1000)) as zmq_:
            probe = AdsProbe(service.ads_address, service.ams_net_id)
            assert ads.wait_closed(1, CLOSE_TIMEOUT_S) == 1
            assert zmq_.wait_closed(1, CLOSE_TIMEOUT_S) == 1
            assert probe.read_device_info() == 0  # its requests complete: never timed out
            probe.close()
        with RawConnection(service.endpoint) as other:
            assert other.call(ReadRequest, *TICK_ADDRESS, 4)[2] == 0
        service.wait_for_log("frame_timeout_s")


def test_connections_beyond_the_cap_are_closed(tmp_path: Path) -> None:
    """``connections_per_front_end`` open connections are served; each one more is
    closed as it comes, on both front ends; once they are gone a new client is served."""
    count = 3 * SMALL_CAP
    with limited_service(tmp_path, ads=True, connections_per_front_end=SMALL_CAP) as service:
        assert service.ads_address is not None and service.ams_net_id is not None
        with Flood(service.ads_address, count, b"") as ads, \
                Flood(_zmq_address(service.endpoint), count, zmtp_greeting()) as zmq_:
            assert ads.wait_closed(count - SMALL_CAP, CLOSE_TIMEOUT_S) >= count - SMALL_CAP
            assert zmq_.wait_closed(count - SMALL_CAP, CLOSE_TIMEOUT_S) >= count - SMALL_CAP
            # the admitted ones stay open: a cap, not a purge
            assert wait_until(ads.closed_by_service, count + 1, 0.5) == count - SMALL_CAP
        service.wait_for_log("connections_per_front_end")
        # their slots are free again: new clients of both front ends are served
        assert _served_within(service.ads_address, service.ams_net_id, CLOSE_TIMEOUT_S)
        with RawConnection(service.endpoint) as other:
            assert other.call(ReadRequest, *TICK_ADDRESS, 4, timeout_s=CLOSE_TIMEOUT_S)[2] == 0


def _served_within(address: tuple[str, int], net_id: str, timeout_s: float) -> bool:
    """A new ADS client is answered within ``timeout_s``: the server frees a slot when it
    has processed the close of a connection, a moment after the client closed it, so a
    connection refused before that is tried again."""
    deadline = time.monotonic() + timeout_s
    while True:
        probe = AdsProbe(address, net_id)
        try:
            return probe.read_device_info() == 0
        except OSError:
            if time.monotonic() > deadline:
                raise
        finally:
            probe.close()
        time.sleep(0.05)
