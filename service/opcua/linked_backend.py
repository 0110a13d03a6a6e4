"""The OPC UA process's view of cnc-service's ``Backend``: exactly what the OPC UA front
end uses of it (``space`` by name, ``direct_read`` / ``read_value``, ``decode_writes`` and
``apply_writes``, ``hub.add`` / ``delete``, ``kernel.config``), served over the private
link to the service (``link_frames``; the service's end is ``host``).

- Reads: an object's getter asks the service for its value and waits for the answer
  (one round trip). A Read of many variables asks for all their objects at once first
  (``prefetched``): one round trip per Read call, not per node.
- Subscriptions: ``hub.add`` asks the service's notification hub (and waits for the
  handle, as the hub answers); its samples come back as NOTIFY frames on the events
  socket and go to the ``notify`` given, as the hub would call it.
- Writes: ``decode_writes`` checks them here with the same address space rules;
  ``apply_writes`` sends them to the service, which decodes them again with its
  ``Backend``, queues them for the kernel and answers when the kernel applied them.

The calls socket is blocking (a getter is called where asyncua cannot wait); the events
socket is the child's event loop's.
"""

from __future__ import annotations

import itertools
import socket
import time
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Any

from cnc_objects.objects import AddressSpace, CncObject, Entry
from cnc_objects.protocol.errors import AdsReturnCode

from .link_frames import FrameBuffer, Link, ReadFailed, frame

WriteResults = list[tuple[int, str]]
#: How long a call asks for its answer without sleeping before it blocks in ``recv`` (s).
#: The service answers in 150-250 us (its loop wakes, some 25 us of work); a process
#: asleep in ``recv`` takes another ~60 us (p50) to wake on this 2-core VM, which is a
#: fifth of the round trip and costs an OPC UA Read of 100 nodes some 6 % of its rate
#: (docs/opcua.md, "Reads"). A Read waits anyway; the spin only uses the waiting time.
ANSWER_SPIN_S = 0.0004


class CallLink:
    """The blocking calls socket: one request, then its answer."""

    def __init__(self, sock: socket.socket) -> None:
        sock.setblocking(True)
        self._sock = sock
        self._frames = FrameBuffer()

    def call(self, message: tuple[Any, ...]) -> tuple[Any, ...]:
        """Send ``message``, wait for the answer; ``ConnectionError`` when the service is
        gone."""
        self._sock.sendall(frame(message))
        spin_until = time.perf_counter() + ANSWER_SPIN_S
        while True:
            flags = socket.MSG_DONTWAIT if time.perf_counter() < spin_until else 0
            try:
                data = self._sock.recv(1 << 16, flags)
            except BlockingIOError:
                continue  # not yet: ask again while the spin lasts
            if not data:
                raise ConnectionError("the service closed the OPC UA link")
            answers = self._frames.feed(data)
            if answers:
                return answers[0]


class LinkedHub:
    """``hub.add`` / ``delete`` of the service's notification hub, over the link."""

    def __init__(self, calls: CallLink, send: Callable[[tuple[Any, ...]], None]) -> None:
        self._calls, self._send = calls, send
        self._keys = itertools.count(1)
        self._notifiers: dict[int, tuple[Callable[..., Any], Any]] = {}
        self._key_of: dict[int, int] = {}  # the hub's handle -> our key

    def add(self, envelope: Any, req: Any, cycle_ns: int, notify: Callable[..., Any]
            ) -> tuple[int, int | str]:
        """Subscribe at the service's hub: (0, handle) or (code, message)."""
        key = next(self._keys)
        self._notifiers[key] = (notify, envelope)  # before: the first sample may come at once
        watch = (req.port, req.group, req.offset, req.length, req.transmission_mode)
        _, code, answer = self._calls.call((Link.SUBSCRIBE, key, envelope, watch, cycle_ns))
        if code:
            del self._notifiers[key]
        else:
            self._key_of[answer] = key
        return code, answer

    def delete(self, envelope: Any, handle: int) -> tuple[int, str]:
        """End a subscription (the service is told; no answer is waited for)."""
        key = self._key_of.pop(handle, None)
        if key is not None:
            del self._notifiers[key]
        self._send((Link.UNSUBSCRIBE, envelope, handle))
        return 0, ""

    def notified(self, key: int, port: int, samples: list[list[Any]]) -> None:
        """A NOTIFY frame: the samples to their ``notify`` (gone: nothing)."""
        found = self._notifiers.get(key)
        if found is not None:
            notify, envelope = found
            notify(envelope, port, samples)


@dataclass(frozen=True)
class KernelFacts:
    """What the front end reads of the kernel: its configuration (``MachineConfig``)."""

    config: Any


class LinkedBackend:
    """The ``Backend`` of the OPC UA process (module docstring)."""

    def __init__(self, objects: Iterable[CncObject], machine_config: Any, calls: CallLink,
                 send: Callable[[tuple[Any, ...]], None]) -> None:
        self._calls, self._send = calls, send
        self._prefetched: dict[int, Any] | None = None
        space = AddressSpace()  # the service's objects, in its order: the same handles
        for obj in objects:
            space.add(obj, self._getter(len(space) + 1) if obj.access.readable else None,
                      _written_by_the_service if obj.access.writable else None)
        self.space = space
        self.kernel = KernelFacts(machine_config)
        self.hub = LinkedHub(calls, send)
        self._writes = itertools.count(1)
        self._pending: dict[int, Callable[[WriteResults], None]] = {}

    # ------------------------------------------------------------ reads

    def _getter(self, handle: int) -> Callable[[], Any]:
        def get() -> Any:
            prefetched = self._prefetched
            if prefetched is not None and handle in prefetched:
                value = prefetched[handle]
            else:
                [value] = self._calls.call((Link.READ, [handle]))[1]
            if isinstance(value, ReadFailed):
                raise RuntimeError(value.message)
            return value

        return get

    @contextmanager
    def prefetched(self, entries: Iterable[Entry]) -> Iterator[None]:
        """Within: the getters of ``entries`` answer what one round trip read for all."""
        handles = list(dict.fromkeys(e.handle for e in entries))
        if not handles or self._prefetched is not None:
            yield
            return
        values = self._calls.call((Link.READ, handles))[1]
        self._prefetched = dict(zip(handles, values))
        try:
            yield
        finally:
            self._prefetched = None

    def direct_read(self, port: int, group: int, offset: int, length: int
                    ) -> tuple[Callable[[], Any], None] | None:
        """The getter of the object at this address when a read of ``length`` answers
        it whole (as ``Backend.direct_read``); None otherwise."""
        found = self.space.find(port, group, offset)
        if isinstance(found, tuple) or found.read is None or length != found.obj.dtype.size:
            return None
        return found.read, None

    def read_value(self, port: int, group: int, offset: int, length: int
                   ) -> tuple[int, Any]:
        """Read at an address of an object: (0, data) or (code, message)."""
        found = self.space.find(port, group, offset)
        if isinstance(found, tuple):
            return found
        return self.space.read_entry_buffer(found, length)

    # ------------------------------------------------------------ writes

    def decode_writes(self, port: int, group: int, offset: int, data: bytes
                      ) -> tuple[int, str, list[tuple[Entry, Any]]]:
        """(0, "", [(entry, data)]) when the address space takes this write (the service
        decodes it again when it applies it), else (code, message, [])."""
        code, target, _ = self.space.decode_write(port, group, offset, data)
        if code:
            return code, str(target), []
        assert isinstance(target, Entry)
        return 0, "", [(target, data)]

    def apply_writes(self, items: list[tuple[Entry, Any]],
                     finish: Callable[[WriteResults], None], holder: Any = None) -> None:
        """Send the writes to the service; ``finish`` gets (code, message) per item on the
        loop once the kernel applied them (``Backend.apply_writes``)."""
        call = next(self._writes)
        self._pending[call] = finish
        self._send((Link.WRITE, call, [(e.handle, data) for e, data in items], holder))

    def written(self, call: int, results: WriteResults) -> None:
        """A WRITTEN frame: the writes of ``call`` are applied or refused."""
        finish = self._pending.pop(call, None)
        if finish is not None:
            finish(results)

    def link_lost(self) -> None:
        """The service is gone: every write waiting is answered as not done."""
        pending, self._pending = self._pending, {}
        for finish in pending.values():
            finish([(AdsReturnCode.DEVICE_NOTREADY, "the service is gone")])


def _written_by_the_service(value: Any) -> Any:
    """The setter of a writable object here: never called (``apply_writes`` sends the
    write to the service, whose kernel applies it)."""
    raise RuntimeError("OPC UA process: writes are applied by the service")

