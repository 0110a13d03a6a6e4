"""The ZeroMQ ADS server: a ROUTER socket on the event loop, dispatch by command id.

Batched pattern: the socket's file descriptor wakes the loop once, then every waiting
frame is drained without blocking and answered in the same pass, so a client with many
requests in flight costs one wake-up per batch, not one await per message. Reads are
answered at once from the kernel's snapshot; writes are queued for the kernel and
answered when the cycle thread has applied them (an acknowledged write is never lost).

Nothing a client sends can stop the server: frames that do not decode get an error reply
(or a logged drop when not even the invoke id can be read), handler faults become ADS
0x700, a vanished client's notifications are dropped.
"""

from __future__ import annotations

import asyncio
import errno
import logging
import struct
from collections.abc import Callable
from typing import Any

import zmq

from objects import AddressSpace, Entry
from protocol import sum as sums
from protocol.constants import MAX_DATA_BYTES, SUM_COMMAND_MAX_ITEMS, AdsCommand, AdsState
from protocol.constants import ReservedIndexGroup as RIG
from protocol.datatypes import STRING_ENCODING
from protocol.errors import AdsReturnCode, ProtocolError
from protocol.frames import (
    AddNotificationRequest,
    BrowseRequest,
    DeleteNotificationRequest,
    ReadRequest,
    ReadWriteRequest,
    Request,
    WriteControlRequest,
    WriteRequest,
    decode_request,
    encode_error,
    encode_response,
)

from . import __version__
from .binding import refusal_code
from .kernel.commands import Refusal
from .kernel.kernel import Control, ControlCommand, Kernel
from .notifications import NotificationHub

log = logging.getLogger(__name__)

_E = AdsReturnCode
_U32 = struct.Struct("<I")
_RESERVED_GROUPS = 0xF000  # index groups from here on are ADS services, not objects
DRAIN_BATCH = 256  # frames handled per wake-up before yielding to other callbacks
DEVICE_NAME = "cnc-objects"
_CONTROLS = {AdsState.RUN: Control.RUN, AdsState.STOP: Control.STOP, AdsState.RESET: Control.RESET}

_NOBLOCK = int(zmq.NOBLOCK)
_SNDMORE_NOBLOCK = int(zmq.SNDMORE | zmq.NOBLOCK)
_EVENTS = int(zmq.EVENTS)
_POLLIN = int(zmq.POLLIN)

Envelope = tuple[bytes, ...]
Reply = bytes | None
ValueResult = tuple[int, Any]  # (0, payload) or (code, message)


class AdsServer:
    """Serves an address space and a kernel on a ZeroMQ ROUTER socket."""

    def __init__(
        self,
        space: AddressSpace,
        kernel: Kernel,
        endpoint: str,
        loop: asyncio.AbstractEventLoop,
        context: zmq.Context | None = None,
    ) -> None:
        self.space = space
        self.kernel = kernel
        self._loop = loop
        self._context = context or zmq.Context()
        self._owns_context = context is None
        sock = self._context.socket(zmq.ROUTER)
        sock.setsockopt(zmq.LINGER, 0)
        sock.setsockopt(zmq.ROUTER_MANDATORY, 1)  # a vanished client raises, not blackholes
        sock.setsockopt(zmq.MAXMSGSIZE, 2 * MAX_DATA_BYTES)  # huge frames cut the peer off
        sock.setsockopt(zmq.SNDHWM, 100_000)
        sock.setsockopt(zmq.RCVHWM, 100_000)
        try:
            sock.bind(endpoint)
        except zmq.ZMQError:
            sock.close()
            if self._owns_context:
                self._context.term()
            raise
        self._sock = sock
        # The Cython socket methods: pyzmq's Python wrappers cost more than the send itself.
        raw = zmq.Socket.__mro__[1]
        self._raw_send = raw.send.__get__(sock)
        self._raw_recv = raw.recv.__get__(sock)
        self._raw_get = raw.get.__get__(sock)
        self.endpoint = sock.getsockopt_string(zmq.LAST_ENDPOINT)
        self._space_read = space.read
        self.hub = NotificationHub(
            self._read_value, self._send, loop, kernel.cycle_ns, lambda: kernel.snapshot
        )
        kernel.on_cycle_end = self.hub.kernel_cycle_end
        self._drain_scheduled = False
        self._handlers: dict[int, Callable[[Envelope, Any], Reply]] = {
            AdsCommand.READ_DEVICE_INFO: self._read_device_info,
            AdsCommand.READ: self._read,
            AdsCommand.WRITE: self._write,
            AdsCommand.READ_STATE: self._read_state,
            AdsCommand.WRITE_CONTROL: self._write_control,
            AdsCommand.ADD_DEVICE_NOTIFICATION: self._add_notification,
            AdsCommand.DELETE_DEVICE_NOTIFICATION: self._delete_notification,
            AdsCommand.READ_WRITE: self._read_write,
            AdsCommand.BROWSE: self._browse,
        }
        self._read_write_groups: dict[int, Callable[[Envelope, ReadWriteRequest], Reply]] = {
            RIG.SUM_READ: self._sum_read,
            RIG.SUM_WRITE: self._sum_write,
            RIG.SUM_READ_WRITE: self._sum_read_write,
        }

    # ------------------------------------------------------------ life cycle

    def start(self) -> None:
        """Begin serving on the loop."""
        self._loop.add_reader(self._sock.FD, self._drain)
        self._schedule_drain()  # frames may already wait; the edge-triggered fd won't say

    def close(self) -> None:
        """Stop serving and close the socket."""
        self.kernel.on_cycle_end = None
        self._loop.remove_reader(self._sock.FD)
        self._sock.close(linger=0)
        if self._owns_context:
            self._context.term()

    # ------------------------------------------------------------ socket

    def _schedule_drain(self) -> None:
        if not self._drain_scheduled:
            self._drain_scheduled = True
            self._loop.call_soon(self._drain)

    def _drain(self) -> None:
        """Handle every waiting frame (up to a batch); each reply goes out at once so a
        pipelining client overlaps its work with ours."""
        self._drain_scheduled = False
        recv, deliver = self._raw_recv, self._deliver
        for _ in range(DRAIN_BATCH):
            try:
                part = recv(_NOBLOCK, False)  # a zmq.Frame: .more is cheaper than RCVMORE
            except zmq.Again:
                break
            frames = [part.bytes]
            while part.more:
                part = recv(_NOBLOCK, False)
                frames.append(part.bytes)
            envelope = tuple(frames[:-1])
            reply = self._handle(envelope, frames[-1])
            if reply is not None:
                deliver(envelope, reply)
        else:
            self._schedule_drain()  # more may wait: come back after other callbacks ran
        self._look_for_input()

    def _look_for_input(self) -> None:
        # ZeroMQ's fd is edge-triggered and a send can consume the edge: look again.
        if self._raw_get(_EVENTS) & _POLLIN:
            self._schedule_drain()

    def _deliver(self, envelope: Envelope, payload: bytes) -> bool:
        send = self._raw_send
        try:
            for part in envelope:
                send(part, _SNDMORE_NOBLOCK)
            send(payload, _NOBLOCK)
        except zmq.ZMQError as exc:
            if exc.errno == errno.EHOSTUNREACH:
                self.hub.drop_client(envelope)
            else:
                log.warning("reply to a client dropped: %s", exc)
            return False
        return True

    def _send(self, envelope: Envelope, payload: bytes) -> bool:
        """Send a frame outside a drain pass; False when it could not be delivered."""
        delivered = self._deliver(envelope, payload)
        self._look_for_input()
        return delivered

    def _handle(self, envelope: Envelope, raw: bytes) -> Reply:
        try:
            request = decode_request(raw)
        except ProtocolError as exc:
            if exc.invoke_id is None:
                log.warning("dropped a frame with no readable invoke id: %s", exc)
                return None
            return encode_error(exc.invoke_id, exc.command or 0, exc.code, str(exc))
        try:
            return self._handlers[request.COMMAND](envelope, request)
        except Exception:
            log.exception("handling %r failed", request)
            return encode_error(
                request.invoke_id, request.COMMAND, _E.DEVICE_ERROR, "internal error; see log"
            )

    @staticmethod
    def _reply(request: Request, result: ValueResult) -> bytes:
        code, payload = result
        if code:
            return encode_error(request.invoke_id, request.COMMAND, code, payload)
        return encode_response(request.invoke_id, request.COMMAND, payload)

    # ------------------------------------------------------------ values

    def _read_value(self, port: int, group: int, offset: int, length: int) -> ValueResult:
        """Read at an address, reserved groups included: (0, data) or (code, message)."""
        if length > MAX_DATA_BYTES:
            return _E.DEVICE_INVALIDSIZE, f"read length {length} exceeds {MAX_DATA_BYTES} bytes"
        if group == RIG.SYM_VALUE_BY_HANDLE:
            entry = self.space.by_handle(offset)
            if entry is None:
                return _E.DEVICE_SYMBOLNOTFOUND, f"handle {offset} is unknown"
            return self.space.read_entry(entry, length)
        return self.space.read(port, group, offset, length)

    def _decode_write(self, port: int, group: int, offset: int, data: bytes) -> tuple:
        """(0, entry, value), (0, None, None) for a handle release, or (code, message, None)."""
        if group == RIG.SYM_VALUE_BY_HANDLE:
            entry = self.space.by_handle(offset)
            if entry is None:
                return _E.DEVICE_SYMBOLNOTFOUND, f"handle {offset} is unknown", None
            return self.space.decode_entry_write(entry, data)
        if group == RIG.SYM_RELEASE_HANDLE:
            if len(data) != 4:
                return _E.DEVICE_INVALIDSIZE, "release a handle by writing its 4 bytes", None
            handle = _U32.unpack(data)[0]
            if self.space.by_handle(handle) is None:
                return _E.DEVICE_SYMBOLNOTFOUND, f"handle {handle} is unknown", None
            return 0, None, None  # handles are stable per object: nothing to free
        return self.space.decode_write(port, group, offset, data)

    def _apply_writes(
        self, items: list[tuple[Entry, Any]], finish: Callable[[list[tuple[int, str]]], None]
    ) -> None:
        """Queue the writes for the kernel; ``finish`` gets (code, message) per item on the
        loop once the cycle thread has applied all of them."""
        results: list[tuple[int, str]] = [(0, "")] * len(items)
        remaining = [len(items)]
        if not items:
            finish(results)
            return

        def applied(k: int, refusal: Refusal | None) -> None:  # runs on the cycle thread
            if refusal is not None:
                results[k] = (refusal_code(refusal), refusal.message)
            remaining[0] -= 1
            if remaining[0] == 0:
                self._loop.call_soon_threadsafe(finish, results)

        for k, (entry, value) in enumerate(items):
            self.kernel.submit(entry.write(value), lambda r, k=k: applied(k, r))

    # ------------------------------------------------------------ commands

    def _read_device_info(self, envelope: Envelope, req: Request) -> Reply:
        major, minor, build = (int(p) for p in __version__.split("."))
        return encode_response(req.invoke_id, req.COMMAND, major, minor, build, DEVICE_NAME)

    def _read(self, envelope: Envelope, req: ReadRequest) -> Reply:
        # The hot path: an object address goes straight to the address space.
        if req.group < _RESERVED_GROUPS:
            code, payload = self._space_read(req.port, req.group, req.offset, req.length)
        else:
            code, payload = self._read_value(req.port, req.group, req.offset, req.length)
        if code:
            return encode_error(req.invoke_id, AdsCommand.READ, code, payload)
        return encode_response(req.invoke_id, AdsCommand.READ, payload)

    def _write(self, envelope: Envelope, req: WriteRequest) -> Reply:
        code, target, value = self._decode_write(req.port, req.group, req.offset, req.data)
        if code:
            return encode_error(req.invoke_id, req.COMMAND, code, target)
        if target is None:
            return encode_response(req.invoke_id, req.COMMAND)

        def finish(results: list[tuple[int, str]]) -> None:
            code, message = results[0]
            if code:
                self._send(envelope, encode_error(req.invoke_id, req.COMMAND, code, message))
            else:
                self._send(envelope, encode_response(req.invoke_id, req.COMMAND))

        self._apply_writes([(target, value)], finish)
        return None

    def _read_state(self, envelope: Envelope, req: Request) -> Reply:
        state = AdsState.RUN if self.kernel.running else AdsState.STOP
        return encode_response(req.invoke_id, req.COMMAND, state, 0)

    def _write_control(self, envelope: Envelope, req: WriteControlRequest) -> Reply:
        control = _CONTROLS.get(req.ads_state)  # type: ignore[call-overload]
        if control is None:
            allowed = ", ".join(f"{s.value} {s.name}" for s in _CONTROLS)
            return encode_error(
                req.invoke_id, req.COMMAND, _E.DEVICE_INVALIDDATA,
                f"ADS state {req.ads_state} cannot be commanded; use {allowed}",
            )

        def done(refusal: Refusal | None) -> None:  # cycle thread
            reply = (
                encode_response(req.invoke_id, req.COMMAND)
                if refusal is None
                else encode_error(req.invoke_id, req.COMMAND, refusal_code(refusal), refusal.message)
            )
            self._loop.call_soon_threadsafe(self._send, envelope, reply)

        self.kernel.submit(ControlCommand(control), done)
        return None

    def _add_notification(self, envelope: Envelope, req: AddNotificationRequest) -> Reply:
        return self._reply(req, self.hub.add(envelope, req))

    def _delete_notification(self, envelope: Envelope, req: DeleteNotificationRequest) -> Reply:
        code, message = self.hub.delete(envelope, req.handle)
        if code:
            return encode_error(req.invoke_id, req.COMMAND, code, message)
        return encode_response(req.invoke_id, req.COMMAND)

    def _browse(self, envelope: Envelope, req: BrowseRequest) -> Reply:
        found = [obj.describe() for obj in self.space.match(req.pattern)]
        return encode_response(req.invoke_id, req.COMMAND, found)

    # ------------------------------------------------------------ read-write

    def _read_write(self, envelope: Envelope, req: ReadWriteRequest) -> Reply:
        if req.read_length > MAX_DATA_BYTES:
            return encode_error(
                req.invoke_id, req.COMMAND, _E.DEVICE_INVALIDSIZE,
                f"read length {req.read_length} exceeds {MAX_DATA_BYTES} bytes",
            )
        handler = self._read_write_groups.get(req.group)
        if handler is not None:  # a sum command
            return handler(envelope, req)
        return self._reply(
            req, self._rw_value(req.port, req.group, req.offset, req.read_length, req.data)
        )

    def _rw_value(self, port: int, group: int, offset: int, read_length: int, data: bytes) -> ValueResult:
        """ReadWrite at one address: handle by name, value by name; others refused."""
        if group in (RIG.SYM_HANDLE_BY_NAME, RIG.SYM_VALUE_BY_NAME):
            try:
                name = data.split(b"\x00", 1)[0].decode(STRING_ENCODING)
            except UnicodeDecodeError:
                return _E.DEVICE_INVALIDDATA, "a symbol name must be CP1252 text"
            entry = self.space.by_name(name)
            if entry is None:
                return _E.DEVICE_SYMBOLNOTFOUND, f"no object is named {name!r}"
            if group == RIG.SYM_VALUE_BY_NAME:
                return self.space.read_entry(entry, read_length)
            if read_length != 4:
                return _E.DEVICE_INVALIDSIZE, "a handle is 4 bytes: read length must be 4"
            return 0, _U32.pack(entry.handle)
        found = self.space.find(port, group, offset)
        if isinstance(found, tuple):
            return found
        return _E.DEVICE_SRVNOTSUPP, f"{found.obj.name} does not take ReadWrite; use Read or Write"

    def _sum_items(self, req: ReadWriteRequest, decode: Callable) -> tuple[int, Any]:
        if not 0 < req.offset <= SUM_COMMAND_MAX_ITEMS:
            return _E.DEVICE_INVALIDPARM, f"a sum command carries 1..{SUM_COMMAND_MAX_ITEMS} items"
        try:
            return 0, decode(req.offset, req.data)
        except ValueError as exc:
            return _E.DEVICE_INVALIDSIZE, str(exc)

    def _sum_read(self, envelope: Envelope, req: ReadWriteRequest) -> Reply:
        code, items = self._sum_items(req, sums.decode_sum_read)
        if code:
            return encode_error(req.invoke_id, req.COMMAND, code, items)
        needed = 4 * len(items) + sum(i.read_length for i in items)
        if req.read_length < needed or needed > MAX_DATA_BYTES:
            return encode_error(
                req.invoke_id, req.COMMAND, _E.DEVICE_INVALIDSIZE,
                f"sum read of these items returns {needed} bytes; read length is {req.read_length}",
            )
        results = []
        for item in items:
            code, data = self._read_value(req.port, item.group, item.offset, item.read_length)
            results.append((code, bytes(item.read_length)) if code else (0, data))
        return encode_response(req.invoke_id, req.COMMAND, sums.encode_sum_read_reply(results))

    def _sum_write(self, envelope: Envelope, req: ReadWriteRequest) -> Reply:
        code, items = self._sum_items(req, sums.decode_sum_write)
        if code:
            return encode_error(req.invoke_id, req.COMMAND, code, items)
        codes: list[int] = [0] * len(items)
        writes: list[tuple[Entry, Any]] = []
        slots: list[int] = []
        for k, item in enumerate(items):
            code, target, value = self._decode_write(req.port, item.group, item.offset, item.data)
            if code:
                codes[k] = code
            elif target is not None:
                writes.append((target, value))
                slots.append(k)

        def finish(results: list[tuple[int, str]]) -> None:
            for k, (code, _) in zip(slots, results):
                codes[k] = code
            reply = encode_response(req.invoke_id, req.COMMAND, sums.encode_codes(codes))
            self._send(envelope, reply)

        self._apply_writes(writes, finish)
        return None

    def _sum_read_write(self, envelope: Envelope, req: ReadWriteRequest) -> Reply:
        code, items = self._sum_items(req, sums.decode_sum_read_write)
        if code:
            return encode_error(req.invoke_id, req.COMMAND, code, items)
        results = []
        for item in items:
            code, data = self._rw_value(req.port, item.group, item.offset, item.read_length, item.data)
            results.append((code, b"") if code else (0, data))
        return encode_response(req.invoke_id, req.COMMAND, sums.encode_sum_read_write_reply(results))
