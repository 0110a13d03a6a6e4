"""``[limits] notification_max_bytes`` and ``notification_bytes_per_client``: a
notification longer than one may be, or one that would take a client's notifications
over its bytes, is refused 0x717 (notification size too large) and subscribes nothing;
deleting one makes room again (issue 35)."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from cnc_objects.objects.catalog import PLC_GROUP
from cnc_objects.protocol.constants import CncPort
from cnc_objects.protocol.frames import DeleteNotificationRequest
from cnc_objects.service.limits import LimitsConfig
from cnc_objects.testing import ServiceProcess
from tests.limits.wire import NOTIFICATIONS, Raw, limited_service, next_id
from tests.support.ads_raw import ADD_NOTIFICATION, RawAds, add_notification
from tests.support.large_notifications import DEFAULTS_LARGEST

INVALIDWATCHSIZE = 0x717
MAX_BYTES, PER_CLIENT_BYTES = 4096, 10_000
GPCH = (CncPort.PLC, PLC_GROUP, 0x10100)  # gpCh: the PLC memory area from its start


@pytest.fixture(scope="module")
def service(tmp_path_factory: pytest.TempPathFactory) -> Iterator[ServiceProcess]:
    with limited_service(tmp_path_factory.mktemp("notification-bytes"),
                         notification_max_bytes=MAX_BYTES,
                         notification_bytes_per_client=PER_CLIENT_BYTES,
                         ads="127.0.0.1:0") as running:
        yield running


def test_the_defaults_let_the_largest_symbol_be_watched_whole() -> None:
    limits = LimitsConfig()
    assert limits.notification_max_bytes == 8192  # gpCh, both channels' HLI structs
    count, length = DEFAULTS_LARGEST  # what the notification-size test and bench use
    assert (limits.notification_bytes_per_client // limits.notification_max_bytes,
            limits.notification_max_bytes) == (count, length)


def test_a_client_over_its_bytes_is_refused_and_deleting_frees_them(
    service: ServiceProcess
) -> None:
    with Raw(service.endpoint) as a, Raw(service.endpoint) as b:
        held = [a.subscribe_on_change(GPCH, MAX_BYTES) for _ in range(2)]
        assert [reply[2] for reply in held] == [0, 0], held
        refused = a.subscribe_on_change(GPCH, MAX_BYTES)  # 12 288 of 10 000 bytes
        assert refused[2] == INVALIDWATCHSIZE, refused
        assert "notification_bytes_per_client" in refused[3] and "8192" in refused[3]
        assert a.read_u32(NOTIFICATIONS) == 2  # nothing subscribed
        assert b.subscribe_on_change(GPCH, MAX_BYTES)[2] == 0  # another client's own bytes
        deleted = a.call(DeleteNotificationRequest(next_id(), CncPort.PLC, held[0][3]).encode())
        assert deleted[2] == 0, deleted
        assert a.subscribe_on_change(GPCH, MAX_BYTES)[2] == 0  # room again


def test_a_notification_longer_than_one_may_be_is_refused(service: ServiceProcess) -> None:
    with Raw(service.endpoint) as client:
        refused = client.subscribe_on_change(GPCH, MAX_BYTES + 1)
        assert refused[2] == INVALIDWATCHSIZE, refused
        assert "notification_max_bytes" in refused[3] and str(MAX_BYTES) in refused[3]
        assert client.subscribe_on_change(GPCH, MAX_BYTES)[2] == 0  # at the limit: taken


def test_ads_gets_0x717_too(service: ServiceProcess) -> None:
    ads = RawAds(service)
    try:
        reply = ads.call(ADD_NOTIFICATION, add_notification(
            PLC_GROUP, GPCH[2], MAX_BYTES + 1, 4, 0), port=CncPort.PLC)
        assert reply.result == INVALIDWATCHSIZE
        reply = ads.call(ADD_NOTIFICATION, add_notification(
            PLC_GROUP, GPCH[2], MAX_BYTES, 4, 0), port=CncPort.PLC)
        assert reply.result == 0
    finally:
        ads.close()
