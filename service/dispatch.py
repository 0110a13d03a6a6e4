"""Dispatch of ADS requests: decoded frame in, reply frame out, by command id.

Transport-neutral: the ZeroMQ server hands every frame to ``Dispatcher.handle`` and sends
what it returns; replies that must wait for the kernel (writes, run control) are sent
later through the ``send`` callback the server supplies. Reads are answered at once from
the kernel's snapshot; writes are queued for the kernel and answered when the cycle
thread has applied them (an acknowledged write is never lost).

Nothing a client sends raises out of here: frames that do not decode get an error reply
(or None, logged, when not even the invoke id can be read), handler faults become 0x700.
"""

from __future__ import annotations

import asyncio
import logging
import struct
from collections.abc import Callable
from typing import Any

from cnc_objects.objects import AddressSpace, Entry
from cnc_objects.protocol import sum as sums
from cnc_objects.protocol.constants import (
    MAX_DATA_BYTES,
    PROGRAM_STORE_GROUP,
    SUM_COMMAND_MAX_ITEMS,
    AdsCommand,
    AdsState,
    CncPort,
)
from cnc_objects.protocol.constants import ReservedIndexGroup as RIG
from cnc_objects.protocol.datatypes import STRING_ENCODING
from cnc_objects.protocol.errors import AdsReturnCode, ProtocolError
from cnc_objects.protocol.frames import (
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
from .notifications import NotificationHub, SendFn
from .program_service import ProgramStoreService

log = logging.getLogger(__name__)

_E = AdsReturnCode
_U32 = struct.Struct("<I")
_RESERVED_GROUPS = 0xF000  # index groups from here on are ADS services, not objects
DEVICE_NAME = "cnc-objects"
_CONTROLS = {AdsState.RUN: Control.RUN, AdsState.STOP: Control.STOP, AdsState.RESET: Control.RESET}

Envelope = tuple[bytes, ...]
Reply = bytes | None
ValueResult = tuple[int, Any]  # (0, payload) or (code, message)


class Dispatcher:
    """Answers ADS requests against an address space and a kernel."""

    def __init__(
        self,
        space: AddressSpace,
        kernel: Kernel,
        loop: asyncio.AbstractEventLoop,
        send: SendFn,
        programs: ProgramStoreService | None = None,
    ) -> None:
        self.space = space
        self.programs = programs
        self.kernel = kernel
        self._loop = loop
        self._send = send
        self._space_read = space.read
        self.hub = NotificationHub(
            self._read_value, send, loop, kernel.cycle_ns, lambda: kernel.snapshot
        )
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

    def handle(self, envelope: Envelope, raw: bytes) -> Reply:
        """The reply to one frame from ``envelope``, or None (sent later, or dropped)."""
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
        if payload is None:  # a write: the reply carries no data
            return encode_response(request.invoke_id, request.COMMAND)
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

    def _is_store(self, port: int, group: int) -> bool:
        return group == PROGRAM_STORE_GROUP and port == CncPort.COM and self.programs is not None

    def _read(self, envelope: Envelope, req: ReadRequest) -> Reply:
        # The hot path: an object address goes straight to the address space.
        if req.group == PROGRAM_STORE_GROUP and self._is_store(req.port, req.group):
            return self._reply(req, self.programs.read(req.offset, req.length))
        if req.group < _RESERVED_GROUPS:
            code, payload = self._space_read(req.port, req.group, req.offset, req.length)
        else:
            code, payload = self._read_value(req.port, req.group, req.offset, req.length)
        if code:
            return encode_error(req.invoke_id, AdsCommand.READ, code, payload)
        return encode_response(req.invoke_id, AdsCommand.READ, payload)

    def _write(self, envelope: Envelope, req: WriteRequest) -> Reply:
        if self._is_store(req.port, req.group):
            return self._reply(req, self.programs.write(req.offset, req.data))
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
        if self._is_store(req.port, req.group):
            return self._reply(req, self.programs.read_write(req.offset, req.data, req.read_length))
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
