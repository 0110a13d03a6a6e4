"""``[limits] max_frame_bytes``: what happens to a ZeroMQ frame at, over and far over it.

The service runs with a 64 KiB limit (hard cap 128 KiB) so that the frames stay small.
"""

from __future__ import annotations

from collections.abc import Iterator

import msgpack
import pytest
import zmq
from zmq.utils.monitor import recv_monitor_message

from cnc_objects.protocol.constants import AdsCommand
from cnc_objects.testing import ServiceProcess
from tests.limits.wire import (
    CHANNELS,
    FEED_OVERRIDE_W,
    REPLY_TIMEOUT_S,
    Raw,
    limited_service,
    next_id,
)
from tests.support.resources import rss_kib

LIMIT_BYTES = 64 << 10
HARD_CAP_BYTES = 2 * LIMIT_BYTES
INVALIDPARM, INVALIDSIZE = 0x70B, 0x705


@pytest.fixture(scope="module")
def service(tmp_path_factory: pytest.TempPathFactory) -> Iterator[ServiceProcess]:
    with limited_service(tmp_path_factory.mktemp("frame-size"), max_frame_bytes=LIMIT_BYTES,
                         program_max_bytes=60_000) as running:
        yield running


def write_frame(total_bytes: int, invoke_id: int) -> bytes:
    """A Write of the feed override whose frame is ``total_bytes`` long."""
    def frame(data_bytes: int) -> bytes:
        return msgpack.packb([invoke_id, AdsCommand.WRITE, *FEED_OVERRIDE_W, bytes(data_bytes)],
                             use_bin_type=True)
    data_bytes = total_bytes - (len(frame(total_bytes)) - total_bytes)
    while len(frame(data_bytes)) < total_bytes:  # msgpack's bin header grows at 64 KiB
        data_bytes += 1
    built = frame(data_bytes)
    assert len(built) == total_bytes
    return built


@pytest.mark.parametrize("size", [LIMIT_BYTES + 1, LIMIT_BYTES + 1000, HARD_CAP_BYTES])
def test_a_frame_over_the_limit_is_answered_0x70b_and_its_client_is_served_on(
    service: ServiceProcess, size: int
) -> None:
    with Raw(service.endpoint) as client:
        invoke_id = next_id()
        reply = client.call(write_frame(size, invoke_id))
        assert reply[:3] == [invoke_id, AdsCommand.WRITE, INVALIDPARM]
        assert f"frame of {size} bytes exceeds the limit of {LIMIT_BYTES}" in reply[3]
        assert client.read(CHANNELS, 2) == b"\x02\x00"


def test_a_frame_at_the_limit_is_served(service: ServiceProcess) -> None:
    with Raw(service.endpoint) as client:
        invoke_id = next_id()
        reply = client.call(write_frame(LIMIT_BYTES, invoke_id))
        # The dispatcher answered: a feed override is 2 bytes, not 64 KiB.
        assert reply[:3] == [invoke_id, AdsCommand.WRITE, INVALIDSIZE]


def test_a_frame_over_the_limit_without_an_invoke_id_gets_no_reply(
    service: ServiceProcess
) -> None:
    with Raw(service.endpoint) as client:
        client.send(b"\x00" * (LIMIT_BYTES + 100))
        # Frames of one client are answered in order: the read's reply comes first.
        assert client.read(CHANNELS, 2) == b"\x02\x00"


def test_a_frame_over_the_hard_cap_cuts_its_client_off_before_it_is_buffered(
    service: ServiceProcess,
) -> None:
    frame_bytes = 32 << 20
    rss_before_kib = rss_kib(service.process.pid)
    with Raw(service.endpoint) as sender, Raw(service.endpoint) as bystander:
        monitor = sender.sock.get_monitor_socket(zmq.EVENT_DISCONNECTED)
        assert sender.read(CHANNELS, 2) == b"\x02\x00"  # connected and served
        sender.send(write_frame(frame_bytes, next_id()))
        assert monitor.poll(int(REPLY_TIMEOUT_S * 1000)), "the sender was not cut off"
        assert recv_monitor_message(monitor)["event"] == zmq.EVENT_DISCONNECTED
        assert bystander.read(CHANNELS, 2) == b"\x02\x00"
        # The sender's DEALER reconnects by itself; the big frame went with the old
        # connection, never answered.
        reply = sender.call(msgpack.packb([next_id(), AdsCommand.READ, *CHANNELS, 2]))
        assert reply[2] == 0
        sender.sock.disable_monitor()
        monitor.close(linger=0)
    growth_kib = rss_kib(service.process.pid) - rss_before_kib
    print(f"\na frame of {frame_bytes >> 20} MiB over the hard cap of {HARD_CAP_BYTES >> 10} "
          f"KiB: service RSS grew by {growth_kib} KiB")
    assert growth_kib < (frame_bytes >> 10) // 4, "the frame was buffered"
