"""Is the service still well? Checked from outside, as a user would: a fresh client gets
correct answers, the kernel cycle advances, the log holds no traceback, the process'
resident memory is what it was.

Everything here talks raw frames over a DEALER socket of its own (``protocol.frames``),
so that a check does not depend on the client library it may be testing, and waits on
replies and samples with timeouts, never for a fixed time.
"""

from __future__ import annotations

import re
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import TypeVar

import msgpack
import zmq

from cnc_objects.protocol.constants import AdsCommand, AdsState, CncPort, TransmissionMode
from cnc_objects.protocol.frames import (
    AddNotificationRequest,
    DeleteNotificationRequest,
    ReadDeviceInfoRequest,
    ReadRequest,
    ReadStateRequest,
)
from cnc_objects.testing import ServiceProcess

REPLY_TIMEOUT_S = 10.0  # one reply on a busy 2-core machine
T = TypeVar("T")
TICK_TIMEOUT_S = 10.0  # the cycle must advance within this (it runs every 1 ms)
#: What the service writes when a thread of it died or a request failed inside it.
FAULT_LINES = re.compile(r"Traceback|cycle thread failed|handling .* failed|Exception in callback")

#: cnc_tick_counter_r: cycles run by the GEO task (port 553, UNS32).
TICK_ADDRESS = (CncPort.COM, 0x120100, 0x1011)


class RawConnection:
    """One DEALER socket to the service, with a ``call`` that waits for its own reply
    (and ignores notifications and other replies that come first)."""

    def __init__(self, endpoint: str, context: zmq.Context | None = None) -> None:
        self.context = context or zmq.Context.instance()
        self.sock = self.context.socket(zmq.DEALER)
        self.sock.setsockopt(zmq.LINGER, 0)
        self.sock.connect(endpoint)
        self._next_id = 1

    def __enter__(self) -> RawConnection:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def close(self) -> None:
        """Close the socket at once."""
        self.sock.close(linger=0)

    def next_id(self) -> int:
        """A fresh invoke id of this connection."""
        self._next_id += 1
        return self._next_id

    def receive(self, timeout_s: float) -> list | None:
        """The next frame as a decoded list, or None after ``timeout_s``."""
        if not self.sock.poll(int(timeout_s * 1000)):
            return None
        return msgpack.unpackb(self.sock.recv(), raw=False)

    def call(self, request_type: type, *fields: object, timeout_s: float = REPLY_TIMEOUT_S) -> list:
        """Send ``request_type(invoke_id, *fields)`` and return its reply
        ``[invoke_id, command, result, ...]``; AssertionError when none comes."""
        invoke_id = self.next_id()
        self.sock.send(request_type(invoke_id, *fields).encode())
        deadline = time.monotonic() + timeout_s
        while (left_s := deadline - time.monotonic()) > 0:
            reply = self.receive(left_s)
            if reply is not None and reply[0] == invoke_id:
                return reply
        raise AssertionError(f"no reply to {request_type.__name__} within {timeout_s:g} s")


@dataclass(frozen=True)
class Vitals:
    """What a fresh client saw: device name and version, ADS state, tick counter."""

    device: tuple
    ads_state: int
    tick: int


def vitals(endpoint: str) -> Vitals:
    """Device info, ADS state and tick counter, read on a fresh connection."""
    with RawConnection(endpoint) as conn:
        info = conn.call(ReadDeviceInfoRequest, CncPort.COM)
        state = conn.call(ReadStateRequest, CncPort.COM)
        tick = conn.call(ReadRequest, *TICK_ADDRESS, 4)
    assert info[2] == 0 and state[2] == 0 and tick[2] == 0, (info, state, tick)
    return Vitals(tuple(info[3:]), state[3], int.from_bytes(tick[3], "little"))


def wait_for_tick_after(endpoint: str, tick: int, timeout_s: float = TICK_TIMEOUT_S) -> int:
    """The first tick counter value above ``tick``, from cyclic samples of
    ``cnc_tick_counter_r`` (every kernel cycle): proof that the cycle runs. Raises
    AssertionError when it has not advanced within ``timeout_s``."""
    with RawConnection(endpoint) as conn:
        reply = conn.call(AddNotificationRequest, *TICK_ADDRESS, 4,
                          int(TransmissionMode.SERVER_CYCLE), 0, 1)
        assert reply[2] == 0, reply
        handle = reply[3]
        deadline = time.monotonic() + timeout_s
        seen = []
        try:
            while (left_s := deadline - time.monotonic()) > 0:
                frame = conn.receive(left_s)
                if frame is None or frame[:2] != [0, AdsCommand.DEVICE_NOTIFICATION]:
                    continue
                for sample_handle, _, _, data in frame[3]:
                    if sample_handle == handle:
                        seen.append(int.from_bytes(data, "little"))
                        if seen[-1] > tick:
                            return seen[-1]
            raise AssertionError(f"the kernel cycle did not advance past tick {tick} within "
                                 f"{timeout_s:g} s (samples seen: {seen[-5:]})")
        finally:
            conn.call(DeleteNotificationRequest, CncPort.COM, handle)


_RECORD_START = re.compile(r"\d{4}-\d\d-\d\d \d\d:\d\d:\d\d")


def log_records(service: ServiceProcess) -> list[str]:
    """The service's log as records: a line with a time stamp and the lines after it
    (a traceback) up to the next stamped line."""
    records: list[str] = []
    for line in service.log:
        if _RECORD_START.match(line) or not records:
            records.append(line)
        else:
            records[-1] += "\n" + line
    return records


def fault_records(service: ServiceProcess) -> list[str]:
    """Log records that say a thread died or a request failed inside the service."""
    return [r for r in log_records(service) if FAULT_LINES.search(r)]


def assert_well(service: ServiceProcess, since_tick: int, baseline: Vitals | None = None
                ) -> Vitals:
    """A fresh client gets the same device info as ``baseline``, the ADS state RUN, a
    cycle that advances past ``since_tick``; the log holds no fault. Returns the
    vitals."""
    now = vitals(service.endpoint)
    if baseline is not None:
        assert now.device == baseline.device, (now, baseline)
    assert now.ads_state == AdsState.RUN, f"ADS state {now.ads_state}, not RUN"
    wait_for_tick_after(service.endpoint, max(since_tick, now.tick))
    faults = fault_records(service)
    assert not faults, "the service logged faults:\n" + "\n".join(faults[:5])
    return now


POLL_S = 0.05  # between two reads of a polled value (wall time)


def poll_until(read: Callable[[], T], done: Callable[[T], bool], timeout_s: float,
               what: str) -> T:
    """Read until ``done(value)``, at most ``timeout_s``; the value. For state that
    cannot be subscribed to (a subscription would itself be refused, or would change
    what is measured), as the client's own ``wait_program`` polls."""
    deadline = time.monotonic() + timeout_s
    seen = []
    while True:
        value = read()
        if done(value):
            return value
        seen.append(value)
        if time.monotonic() > deadline:
            raise AssertionError(f"{what} not reached within {timeout_s:g} s; "
                                 f"last values: {seen[-5:]}")
        time.sleep(POLL_S)
