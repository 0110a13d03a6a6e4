"""Notifications are not duplicated: an on-change subscription gets the current value
once, then a sample per change, never the same unchanged value twice.
"""

from __future__ import annotations

from collections import Counter

import pytest

from cnc_objects.protocol.constants import AdsCommand, CncPort, TransmissionMode
from cnc_objects.protocol.frames import AddNotificationRequest
from cnc_objects.testing import ServiceProcess, serving
from tests.reliability.health import RawConnection, vitals, wait_for_tick_after

SUBSCRIPTIONS = 1000  # one client's allowance, opened back to back
CONSTANT = (CncPort.COM, 0x120101, 0xA, 2)  # ch1.mc_command_feed_override_r: nobody writes it
SETTLE_CYCLES = 200  # kernel cycles after the last acknowledgement: every sample is out


@pytest.fixture(scope="module")
def service() -> ServiceProcess:
    with serving() as running:
        yield running


def test_an_on_change_subscription_gets_an_unchanged_value_once(service: ServiceProcess) -> None:
    samples: Counter[int] = Counter()
    with RawConnection(service.endpoint) as conn:
        for invoke_id in range(1, SUBSCRIPTIONS + 1):
            conn.sock.send(AddNotificationRequest(
                invoke_id, *CONSTANT, int(TransmissionMode.SERVER_ON_CHANGE), 0, 0).encode())
        handles = set()
        while len(handles) < SUBSCRIPTIONS:
            frame = conn.receive(10.0)
            assert frame is not None, f"{len(handles)} of {SUBSCRIPTIONS} acknowledged"
            if frame[:2] == [0, AdsCommand.DEVICE_NOTIFICATION]:
                samples.update(handle for handle, *_ in frame[3])
            else:
                assert frame[2] == 0, frame
                handles.add(frame[3])
        wait_for_tick_after(service.endpoint, vitals(service.endpoint).tick + SETTLE_CYCLES)
        while (frame := conn.receive(0.0)) is not None:  # what has come meanwhile
            if frame[:2] == [0, AdsCommand.DEVICE_NOTIFICATION]:
                samples.update(handle for handle, *_ in frame[3])
    assert set(samples) == handles, "every subscription gets its first sample"
    twice = [h for h, n in samples.items() if n > 1]
    assert not twice, f"{len(twice)} of {SUBSCRIPTIONS} subscriptions got the value again"

