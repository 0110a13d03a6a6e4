"""A monitor that subscribes on change to a large range of the PLC memory area, and
another client's reads beside it: what the notification-size test
(tests/reliability/test_notification_size.py) and the bench (``make bench``, part
``fairness``) measure (issue 35).

The range starts at gpCh (port 851, 0x4020, 0x10100), the first symbol of the PLC
memory area: one read of it reads every symbol in the range, about a kernel cycle or
more for 8 KiB and up. The monitor never reads its samples (the service must not care).
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager

from cnc_objects.objects.catalog import PLC_GROUP
from cnc_objects.protocol.constants import CncPort, TransmissionMode
from cnc_objects.protocol.frames import AddNotificationRequest
from cnc_objects.testing import ServiceProcess
from tests.limits.wire import Raw, next_id
from tests.support.ads_raw import ADD_NOTIFICATION, RawAds, add_notification
from tests.support.notification_load import ads_read_latencies_s, read_latencies_s

GPCH_OFFSET = 0x10100  # gpCh, the first symbol of the PLC memory area
#: The attack's length by front end (the largest each wire lets through: what one AMS
#: frame carries comfortably; from gpCh to the end of the area).
ATTACK_BYTES = {"ads": 60_000, "zmq": 460_032}
ATTACKS = 20  # 2 % of notifications_per_client
#: The largest subscriptions the default limits take: 64 KiB per client
#: (notification_bytes_per_client) in notifications of 8 KiB (notification_max_bytes,
#: gpCh whole); tests/limits/test_notification_bytes.py checks the defaults say so.
DEFAULTS_LARGEST = (8, 8192)
#: The clock the attack needs: 1 ms cycles in wall time, a read of the range longer
#: than one (the virtual clock does not publish while a pass is scheduled).
REALTIME = ("--clock", "realtime")


class Monitor:
    """One client connection on ``front_end`` (``ads`` or ``zmq``) that subscribes to
    the PLC memory area on change."""

    def __init__(self, service: ServiceProcess, front_end: str) -> None:
        self.ads: RawAds | None = None
        self.raw: Raw | None = None
        if front_end == "ads":
            self.ads = RawAds(service)
        else:
            self.raw = Raw(service.endpoint)

    def close(self) -> None:
        """Close the connection (its notifications go with it)."""
        if self.ads is not None:
            self.ads.close()
        if self.raw is not None:
            self.raw.close()

    def subscribe(self, length: int) -> tuple[int, str]:
        """AddDeviceNotification on change, every cycle, of ``length`` bytes from gpCh:
        (ADS result, the refusal's message over ZeroMQ, else "")."""
        if self.ads is not None:
            reply = self.ads.call(ADD_NOTIFICATION, add_notification(
                PLC_GROUP, GPCH_OFFSET, length, TransmissionMode.SERVER_ON_CHANGE, 0),
                port=CncPort.PLC)
            return reply.result, ""
        assert self.raw is not None
        answer = self.raw.call(AddNotificationRequest(
            next_id(), CncPort.PLC, PLC_GROUP, GPCH_OFFSET, length,
            TransmissionMode.SERVER_ON_CHANGE, 0, 0).encode())
        return answer[2], answer[3] if answer[2] else ""


@contextmanager
def monitor(service: ServiceProcess, front_end: str) -> Iterator[Monitor]:
    """A ``Monitor`` for a ``with`` block."""
    client = Monitor(service, front_end)
    try:
        yield client
    finally:
        client.close()


def read_latencies(service: ServiceProcess, front_end: str, count: int) -> list[float]:
    """``count`` plain reads of another client on ``front_end``, one at a time."""
    if front_end == "ads":
        assert service.ads_address is not None and service.ams_net_id is not None
        return ads_read_latencies_s(service.ads_address, service.ams_net_id, count)
    return read_latencies_s(service.endpoint, count)
