"""``[limits] notifications_per_client`` and ``notifications_total``, the objects that count
open notifications, and a killed client's notifications being freed."""

from __future__ import annotations

import signal
import socket
import struct
import subprocess
import sys
from collections.abc import Iterator

import msgpack
import pytest

from cnc_objects.protocol.constants import AdsCommand, TransmissionMode
from cnc_objects.protocol.frames import AddNotificationRequest, DeleteNotificationRequest
from cnc_objects.testing import ServiceProcess
from tests.limits.wire import (
    CHANNELS,
    NOTIFICATION_CLIENTS,
    NOTIFICATIONS,
    Raw,
    limited_service,
    next_id,
    wait_until,
)
from tests.support.ads_raw import ADD_NOTIFICATION, COM, RawAds, add_notification

PER_CLIENT, TOTAL = 5, 8
NOMOREHDLS = 0x716
FREED_TIMEOUT_S = 15.0  # a vanished ZeroMQ client is noticed by the next send to it


@pytest.fixture(scope="module")
def service(tmp_path_factory: pytest.TempPathFactory) -> Iterator[ServiceProcess]:
    with limited_service(tmp_path_factory.mktemp("notifications"),
                         notifications_per_client=PER_CLIENT, notifications_total=TOTAL,
                         ads="127.0.0.1:0") as running:
        yield running


def counts(client: Raw) -> tuple[int, int]:
    """(open notifications, clients holding any), as the service's objects say."""
    return client.read_u32(NOTIFICATIONS), client.read_u32(NOTIFICATION_CLIENTS)


def test_a_client_over_its_share_and_the_service_over_its_total_get_0x716(
    service: ServiceProcess
) -> None:
    with Raw(service.endpoint) as a, Raw(service.endpoint) as b, Raw(service.endpoint) as c:
        assert counts(c) == (0, 0)
        handles = [a.subscribe_on_change(CHANNELS, 2) for _ in range(PER_CLIENT)]
        assert all(reply[2] == 0 for reply in handles), handles
        refused = a.subscribe_on_change(CHANNELS, 2)
        assert refused[2] == NOMOREHDLS and "notifications_per_client" in refused[3]
        assert counts(c) == (PER_CLIENT, 1)

        for _ in range(TOTAL - PER_CLIENT):
            assert b.subscribe_on_change(CHANNELS, 2)[2] == 0
        refused = b.subscribe_on_change(CHANNELS, 2)  # b holds 3 of its 5: the total is full
        assert refused[2] == NOMOREHDLS and "notifications_total" in refused[3]
        assert counts(c) == (TOTAL, 2)

        handle = handles[0][3]
        assert a.call(DeleteNotificationRequest(next_id(), CHANNELS[0], handle).encode())[2] == 0
        assert b.subscribe_on_change(CHANNELS, 2)[2] == 0  # room again
        assert counts(c) == (TOTAL, 2)
    with Raw(service.endpoint) as c:  # a and b are gone: their notifications are freed
        wait_until(lambda: counts(c) == (0, 0), FREED_TIMEOUT_S, "notifications freed")


def test_parts_a_client_puts_before_its_frames_do_not_make_it_several_clients(
    service: ServiceProcess
) -> None:
    """Limits count per connection: a client that sends ``[prefix, frame]`` with three
    prefixes is still one client (and gets each reply with its prefix back)."""
    accepted = 0
    with Raw(service.endpoint) as client, Raw(service.endpoint) as watcher:
        for k in range(3 * PER_CLIENT):
            invoke_id, prefix = next_id(), b"abc"[k % 3:k % 3 + 1]
            client.sock.send_multipart([prefix, AddNotificationRequest(
                invoke_id, *CHANNELS, 2, TransmissionMode.SERVER_ON_CHANGE, 0, 0).encode()])
            while True:  # samples come in between
                got_prefix, frame = client.sock.recv_multipart()
                reply = msgpack.unpackb(frame)
                if reply[0] == invoke_id:
                    break
            assert got_prefix == prefix
            accepted += reply[2] == 0
        assert accepted == PER_CLIENT
        assert counts(watcher) == (PER_CLIENT, 1)
    with Raw(service.endpoint) as watcher:
        wait_until(lambda: counts(watcher) == (0, 0), FREED_TIMEOUT_S, "notifications freed")


_KILLED_CLIENT = """
import sys, msgpack, zmq
from cnc_objects.protocol.constants import TransmissionMode
from cnc_objects.protocol.frames import AddNotificationRequest
sock = zmq.Context().socket(zmq.DEALER)
sock.connect(sys.argv[1])
for k in range(1, int(sys.argv[2]) + 1):  # on change, of a value that never changes
    sock.send(AddNotificationRequest(k, 553, 0x120100, 0x1002, 2,
                                     TransmissionMode.SERVER_ON_CHANGE, 0, 0).encode())
answered = set()
while len(answered) < int(sys.argv[2]):
    reply = msgpack.unpackb(sock.recv())
    if reply[0]:
        assert reply[2] == 0, reply
        answered.add(reply[0])
print("subscribed", flush=True)
sys.stdin.read()  # until killed
"""


def test_a_killed_clients_notifications_are_freed(service: ServiceProcess) -> None:
    """A client SIGKILLed with notifications open (on change, of a value that never
    changes: nothing would ever be sent to it) no longer holds them."""
    client = subprocess.Popen(
        [sys.executable, "-c", _KILLED_CLIENT, service.endpoint, str(PER_CLIENT)],
        stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True,
    )
    try:
        assert client.stdout.readline().strip() == "subscribed"  # type: ignore[union-attr]
        with Raw(service.endpoint) as watcher:
            assert counts(watcher) == (PER_CLIENT, 1)
            client.send_signal(signal.SIGKILL)
            client.wait(10)
            wait_until(lambda: counts(watcher) == (0, 0), FREED_TIMEOUT_S,
                       "the killed client's notifications freed")
    finally:
        if client.poll() is None:
            client.kill()
            client.wait()


def test_an_ads_connection_that_drops_frees_its_notifications(service: ServiceProcess) -> None:
    ads = RawAds(service)
    try:
        for _ in range(3):
            reply = ads.call(ADD_NOTIFICATION, add_notification(0x120100, 0x1002, 2, 4, 10_000),
                             port=COM)
            assert reply.result == 0
        with Raw(service.endpoint) as watcher:
            assert counts(watcher) == (3, 1)
            # Linger 0: the close resets the connection, as a crash would.
            ads.sock.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))
            ads.close()
            wait_until(lambda: counts(watcher) == (0, 0), FREED_TIMEOUT_S,
                       "the ADS client's notifications freed")
    finally:
        ads.close()


def test_the_limits_count_both_front_ends_together(service: ServiceProcess) -> None:
    ads = RawAds(service)
    try:
        with Raw(service.endpoint) as zmq_client:
            for _ in range(PER_CLIENT):
                assert zmq_client.subscribe_on_change(CHANNELS, 2)[2] == 0
            for _ in range(TOTAL - PER_CLIENT):
                reply = ads.call(ADD_NOTIFICATION,
                                 add_notification(0x120100, 0x1002, 2, 4, 10_000), port=COM)
                assert reply.result == 0
            reply = ads.call(ADD_NOTIFICATION, add_notification(0x120100, 0x1002, 2, 4, 10_000),
                             port=COM)
            assert reply.result == NOMOREHDLS
            assert counts(zmq_client) == (TOTAL, 2)
            assert reply.command == AdsCommand.ADD_DEVICE_NOTIFICATION
    finally:
        ads.close()
    with Raw(service.endpoint) as watcher:
        wait_until(lambda: counts(watcher) == (0, 0), FREED_TIMEOUT_S, "notifications freed")
