"""A client process killed with SIGKILL mid-flight, with subscriptions open: its
notifications are freed and the next clients get their full allowance.

The child (``subscriber_child.py``) opens as many notifications as the service takes in
all (``notifications_total``, over ``notifications_per_client``-sized connections), all
on change of a value that never changes (the hard case: nothing is ever sent to them, so
nothing but the service's own probing can notice that their client is gone), then
floods the service with requests whose replies it never reads, and is killed. The count
of open notifications (``cnc_notifications_r``) must fall back to what it was, and a
fresh client must then open its full allowance. Run once killed mid-flight (its
requests on the wire) and once killed while idle.
"""

from __future__ import annotations

import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from cnc_objects.clients import Client
from cnc_objects.protocol.constants import TransmissionMode
from cnc_objects.protocol.errors import AdsReturnCode
from cnc_objects.protocol.frames import AddNotificationRequest
from cnc_objects.testing import ServiceProcess, serving
from tests.reliability import figures
from tests.reliability.health import RawConnection, assert_well, poll_until, vitals
from tests.reliability.scale import Scale
from tests.support.child_output import read_line

PER_CLIENT = 1000  # default [limits] notifications_per_client
TOTAL = 20_000  # default [limits] notifications_total
CHILD = Path(__file__).with_name("subscriber_child.py")
SUBSCRIBE_TIMEOUT_S = 120.0  # the child opens TOTAL notifications on a busy machine
FREED_TIMEOUT_S = 30.0  # the service notices a vanished client (it probes every 2 s)
CONSTANT = "ch1.mc_command_feed_override_r"  # nothing changes it in this test
COUNT = "cnc_notifications_r"
NODE = "tests/reliability/test_killed_client.py"


@pytest.fixture(scope="module")
def service() -> ServiceProcess:
    with serving() as running:
        yield running


def open_allowance(endpoint: str, address: tuple[int, int, int, int]) -> int:
    """Open PER_CLIENT on-change notifications on one fresh connection; how many were
    acknowledged (the connection closes afterwards: the service frees them)."""
    opened = 0
    with RawConnection(endpoint) as conn:
        for _ in range(PER_CLIENT):
            reply = conn.call(AddNotificationRequest, *address,
                              int(TransmissionMode.SERVER_ON_CHANGE), 0, 1000)
            if reply[2] != 0:
                assert reply[2] == AdsReturnCode.DEVICE_NOMOREHDLS, reply
                break
            opened += 1
    return opened


@pytest.mark.parametrize("traffic", ["flood", "idle"])
def test_a_killed_client_frees_its_notifications(
    service: ServiceProcess, run_scale: Scale, traffic: str
) -> None:
    """``flood``: killed with its requests on the wire, so replies to it fail at once;
    ``idle``: killed quietly, so only the service's probing can notice."""
    before = vitals(service.endpoint)
    with Client(service.endpoint, timeout_s=20) as client:
        info = client.describe(CONSTANT)
        address = (info.port, info.group, info.offset, info.length)
        baseline = client.read(COUNT)
        freed_s = []
        for _ in range(run_scale.killed_clients):
            child = subprocess.Popen(
                [sys.executable, str(CHILD), service.endpoint, str(TOTAL // PER_CLIENT),
                 str(PER_CLIENT), *(str(v) for v in address), traffic],
                stdout=subprocess.PIPE, text=True)
            try:
                line = read_line(child, SUBSCRIBE_TIMEOUT_S)
                assert line == f"subscribed {TOTAL}", line
                assert client.read(COUNT) == baseline + TOTAL
                # the service's total is taken: a fresh client gets no notification
                assert open_allowance(service.endpoint, address) == 0
            finally:
                child.send_signal(signal.SIGKILL)  # mid-flight: its reads are on the wire
                child.wait()
            killed = time.monotonic()
            # polled: while the total is taken a subscription to the count is refused
            poll_until(lambda: client.read(COUNT), lambda n: n == baseline, FREED_TIMEOUT_S,
                       f"{COUNT} == {baseline}")
            freed_s.append(time.monotonic() - killed)
            assert open_allowance(service.endpoint, address) == PER_CLIENT
            # that connection is gone too: the next child needs the whole total again
            poll_until(lambda: client.read(COUNT), lambda n: n == baseline, FREED_TIMEOUT_S,
                       f"{COUNT} == {baseline} after the allowance's connection closed")
    assert_well(service, before.tick, before)
    print(f"\n{run_scale.killed_clients} client processes ({traffic}) with {TOTAL} "
          f"notifications each killed: freed after {', '.join(f'{s:.1f}' for s in freed_s)} s")
    figures.record(f"SIGKILLed client ({traffic}), {TOTAL} notifications: freed within",
                   f"{max(freed_s):.1f} s ({run_scale.killed_clients} kills)", NODE)

