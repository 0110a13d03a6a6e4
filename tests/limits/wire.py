"""Raw frames to a real service for the limit tests: a DEALER of its own, a service with a
``[limits]`` table, the service's memory, a client that floods from another process.

Raw frames (``protocol.frames``), not the client library: the tests send what a client
library would refuse to send (oversized frames, thousands of requests without waiting).
"""

from __future__ import annotations

import itertools
import multiprocessing
import struct
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import msgpack
import zmq

from cnc_objects.protocol.constants import AdsCommand, CncPort, TransmissionMode
from cnc_objects.protocol.frames import AddNotificationRequest, ReadRequest, WriteRequest
from cnc_objects.testing import ServiceProcess, serving

REPLY_TIMEOUT_S = 10.0  # one reply on a busy 2-core machine
PLATFORM = 0x120100  # COM platform objects (cnc_*)
CH1_COM = 0x120101  # COM objects of channel 1
TICK = (CncPort.COM, PLATFORM, 0x1011)  # cnc_tick_counter_r, UNS32
OVERRUNS = (CncPort.COM, PLATFORM, 0x1012)  # cnc_cycle_overruns_r, UNS32
NOTIFICATIONS = (CncPort.COM, PLATFORM, 0x1017)  # cnc_notifications_r, UNS32
NOTIFICATION_CLIENTS = (CncPort.COM, PLATFORM, 0x1018)  # cnc_notification_clients_r, UNS32
CHANNELS = (CncPort.COM, PLATFORM, 0x1002)  # cnc_number_of_channel_r, UNS16: constant
FEED_OVERRIDE_W = (CncPort.COM, CH1_COM, 0x09)  # UNS16 0.1 %
FEED_OVERRIDE_R = (CncPort.COM, CH1_COM, 0x0A)  # UNS16 0.1 %
ERROR_TEXT = (CncPort.COM, CH1_COM, 0x3031)  # mc_error_1_text_r, STRING(256)

_ids = itertools.count(1)


def next_id() -> int:
    """A fresh invoke id."""
    return next(_ids)


def read_frame(address: tuple[int, int, int], length: int, invoke_id: int = 0) -> bytes:
    """A Read request frame."""
    return ReadRequest(invoke_id or next_id(), *address, length).encode()


def limits_toml(path: Path, **limits: Any) -> Path:
    """A configuration file at ``path`` with a ``[limits]`` table of ``limits``."""
    lines = ["[limits]", *(f"{key} = {value!r}" for key, value in limits.items())]
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


@contextmanager
def limited_service(tmp_path: Path, *args: str, ads: bool | str = False,
                    **limits: Any) -> Iterator[ServiceProcess]:
    """A service with ``[limits]`` ``limits`` (virtual clock unless ``args`` say else;
    ``ads`` as ``start_service`` takes it)."""
    config = limits_toml(tmp_path / "limits.toml", **limits)
    with serving("--config", str(config), *args, ads=ads) as service:
        yield service


class Raw:
    """One DEALER socket to the service, speaking raw frames."""

    def __init__(self, endpoint: str, **options: int) -> None:
        self.context = zmq.Context.instance()
        self.sock = self.context.socket(zmq.DEALER)
        self.sock.setsockopt(zmq.LINGER, 0)
        for name, value in options.items():
            self.sock.setsockopt(getattr(zmq, name), value)
        self.sock.connect(endpoint)

    def __enter__(self) -> Raw:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def close(self) -> None:
        """Close at once."""
        self.sock.close(linger=0)

    def send(self, frame: bytes) -> None:
        """Send one frame."""
        self.sock.send(frame)

    def receive(self, timeout_s: float = REPLY_TIMEOUT_S) -> list | None:
        """The next frame, decoded; None after ``timeout_s``."""
        if not self.sock.poll(int(timeout_s * 1000)):
            return None
        return msgpack.unpackb(self.sock.recv(), raw=False)

    def reply(self, invoke_id: int, timeout_s: float = REPLY_TIMEOUT_S) -> list:
        """The reply to ``invoke_id`` (notifications before it are skipped)."""
        deadline = time.monotonic() + timeout_s
        while True:
            got = self.receive(max(deadline - time.monotonic(), 0.0))
            assert got is not None, f"no reply to invoke id {invoke_id} within {timeout_s} s"
            if got[0] == invoke_id:
                return got
            assert got[0] == 0, f"reply to {got[0]} while waiting for {invoke_id}"

    def call(self, frame: bytes, timeout_s: float = REPLY_TIMEOUT_S) -> list:
        """Send ``frame`` and return its reply."""
        self.send(frame)
        return self.reply(msgpack.unpackb(frame)[0], timeout_s)

    def read(self, address: tuple[int, int, int], length: int) -> bytes:
        """The value at ``address`` (asserts success)."""
        reply = self.call(read_frame(address, length))
        assert reply[2] == 0, reply
        return reply[3]

    def read_u32(self, address: tuple[int, int, int]) -> int:
        """An UNS32 object."""
        return struct.unpack("<I", self.read(address, 4))[0]

    def write_u16(self, address: tuple[int, int, int], value: int) -> list:
        """Write an UNS16 object; the reply."""
        return self.call(WriteRequest(next_id(), *address, struct.pack("<H", value)).encode())

    def subscribe_on_change(self, address: tuple[int, int, int], length: int) -> list:
        """AddDeviceNotification on change, every cycle; the reply."""
        return self.call(AddNotificationRequest(
            next_id(), *address, length, TransmissionMode.SERVER_ON_CHANGE, 0, 0).encode())


def wait_until(check: Any, timeout_s: float, what: str) -> Any:
    """Poll ``check()`` until it returns something true; AssertionError after the timeout
    (the value last seen in the message)."""
    deadline = time.monotonic() + timeout_s
    while True:
        value = check()
        if value:
            return value
        assert time.monotonic() < deadline, f"{what} within {timeout_s} s (last: {value!r})"
        time.sleep(0.02)


# ------------------------------------------------------------------ a flooding client


def _flood(endpoint: str, frame: bytes, in_flight: int, started: Any, stop: Any,
           sent: Any) -> None:
    """Keep ``in_flight`` copies of ``frame`` outstanding until ``stop`` is set."""
    context = zmq.Context()
    sock = context.socket(zmq.DEALER)
    sock.setsockopt(zmq.LINGER, 0)
    sock.connect(endpoint)
    outstanding = count = 0
    started.set()
    while not stop.is_set():
        while outstanding < in_flight:
            sock.send(frame)
            outstanding += 1
            count += 1
        while sock.poll(100 if outstanding >= in_flight else 0):
            sock.recv()
            outstanding -= 1
    sent.value = count
    sock.close(linger=0)
    context.term()


@contextmanager
def flooding(endpoint: str, frame: bytes, in_flight: int = 1000) -> Iterator[Any]:
    """A client in another process that keeps ``in_flight`` requests outstanding (it sends
    again as soon as a reply comes); yields a value holding how many it sent, set when it
    has stopped."""
    spawn = multiprocessing.get_context("spawn")
    started, stop, sent = spawn.Event(), spawn.Event(), spawn.Value("q", 0)
    process = spawn.Process(target=_flood, args=(endpoint, frame, in_flight, started, stop, sent),
                            name="flooding-client", daemon=True)
    process.start()
    try:
        assert started.wait(30), "the flooding client did not start"
        yield sent
    finally:
        stop.set()
        process.join(30)
        if process.is_alive():
            process.kill()
            process.join()


def read_many_frame(address: tuple[int, int, int], length: int, items: int) -> bytes:
    """A sum read (ReadWrite 0xF080) of ``items`` reads of ``address``."""
    port, group, offset = address
    data = struct.pack("<III", group, offset, length) * items
    return msgpack.packb(
        [next_id(), AdsCommand.READ_WRITE, port, 0xF080, items, items * (4 + length), data],
        use_bin_type=True)
