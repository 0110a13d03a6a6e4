"""Dispatch of ADS requests: a decoded request in, the reply frame out, by command id.

Transport-neutral: each front end decodes its frames into the request tuples of
``protocol.frames`` (ZeroMQ from msgpack, ADS over AMS/TCP from the AMS payload) and
hands them to its own ``Dispatcher``; the dispatcher answers through the front end's
``FrontEnd`` (how a reply, an error and a notification are encoded and sent), so the
command logic exists once for both wires. Reads are answered at once from the kernel's
snapshot; writes are queued for the kernel and answered when the cycle thread has
applied them (an acknowledged write is never lost), through ``FrontEnd.send``.

Access is decided here, once for both wires (``protocol.roles``): a front end that knows
who its peer is calls ``dispatch_as`` with the peer's role (ZeroMQ: the role of its CURVE
key; ADS: the role of its route); a request beyond the role gets ADS 0x704 naming the
role, each item of a sum write in its own slot, and the connection stays. ``dispatch``
serves everything: front ends without access control (no keys, loopback only) call it,
so their hot path pays nothing for the policy.

Nothing a client sends raises out of here: handler faults become 0x700.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from enum import IntEnum
from typing import Any, Protocol, cast

from cnc_objects.objects import Entry
from cnc_objects.protocol import sum as sums
from cnc_objects.protocol.constants import (
    MAX_DATA_BYTES,
    OUTPUT_AREA_GROUP,
    PROGRAM_STORE_GROUP,
    SUM_COMMAND_MAX_ITEMS,
    AdsCommand,
    AdsState,
    AmsPort,
    CncPort,
)
from cnc_objects.protocol.constants import ReservedIndexGroup as RIG
from cnc_objects.protocol.errors import AdsReturnCode
from cnc_objects.protocol.frames import (
    BrowseRequest,
    DeleteNotificationRequest,
    ReadRequest,
    ReadWriteRequest,
    Request,
    WriteControlRequest,
    WriteRequest,
)
from cnc_objects.protocol.roles import COMMAND_ROLES, Role, role_to_write, roles_that_may

from . import __version__
from .backend import Backend, ValueResult
from .binding import refusal_code
from .kernel.commands import Refusal
from .kernel.kernel import Control, ControlCommand
from .notifications import Envelope
from .output_service import OutputService
from .program_service import ProgramStoreService

log = logging.getLogger(__name__)

_E = AdsReturnCode
_RESERVED_GROUPS = 0xF000  # index groups from here on are ADS services, not objects
DEVICE_NAME = "cnc-objects"
_CONTROLS = {AdsState.RUN: Control.RUN, AdsState.STOP: Control.STOP, AdsState.RESET: Control.RESET}
_ADMIN = Role.ADMIN
_READ_WRITE = AdsCommand.READ_WRITE
_SYSTEM_SERVICE = AmsPort.SYSTEM_SERVICE

Reply = bytes | None
#: Browse patterns whose answers are kept (the catalogue described); more start over.
BROWSE_PATTERNS_KEPT = 16


def _as_tuples(value: Any) -> Any:
    """``value`` with every list in it a tuple and every int enum an int: msgpack packs
    them alike, and a tuple of atoms is one the collector stops tracking."""
    if isinstance(value, list):
        return tuple(_as_tuples(v) for v in value)
    return int(value) if isinstance(value, IntEnum) else value


class FrontEnd(Protocol):
    """A front end's wire, as the dispatcher needs it."""

    def ok(self, envelope: Envelope, req: Any, *fields: Any) -> bytes:
        """The successful reply to ``req`` with the command's response fields."""
        ...

    def error(self, envelope: Envelope, req: Any, code: int, message: str) -> bytes:
        """The error reply to ``req``: ADS ``code`` and a sentence saying why."""
        ...

    def send(self, envelope: Envelope, payload: bytes) -> bool:
        """Send a reply later (after the kernel applied a write); False if undelivered."""
        ...

    def notify(self, envelope: Envelope, port: int, samples: list[list[Any]]) -> bool:
        """Encode and send notification samples ``[handle, sequence, FILETIME, data]``."""
        ...

    def cycle_ns(self, req: Any) -> int:
        """The cycle time of an AddDeviceNotification request, in ns (its wire's unit
        converted)."""
        ...

    #: Wall time between the reply to AddDeviceNotification and the first sample (s).
    first_sample_delay_s: float


class Dispatcher:
    """Answers one front end's ADS requests against the shared ``Backend``."""

    def __init__(self, backend: Backend, front: FrontEnd) -> None:
        self.backend = backend
        self.space = backend.space
        self.kernel = backend.kernel
        self.programs = backend.programs
        self.outputs = backend.outputs
        self.files = backend.files
        self.hub = backend.hub
        self._loop = backend.loop
        self._front = front
        self._ok = front.ok
        self._error = front.error
        self._send = front.send
        self._space_read = backend.space.read
        self._read_value = backend.read_value
        self._browsed: dict[str, list[Any]] = {}  # pattern -> its objects described
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

    def dispatch(self, envelope: Envelope, request: Request) -> Reply:
        """The reply to ``request`` from ``envelope``, or None (sent later through
        ``FrontEnd.send``)."""
        try:
            return self._handlers[request.COMMAND](envelope, request)
        except Exception:
            log.exception("handling %r failed", request)
            return self._error(envelope, request, _E.DEVICE_ERROR, "internal error; see log")

    def dispatch_as(self, envelope: Envelope, request: Request, role: Role) -> Reply:
        """``dispatch`` for a peer of ``role``: a request beyond the role is answered ADS
        0x704 with a sentence naming the role (a sum write: 0x704 in each slot beyond it)."""
        if role is _ADMIN:  # may everything
            return self.dispatch(envelope, request)
        try:
            command = request.COMMAND
            if command == _READ_WRITE:  # reads, but for a sum write's items
                return self._read_write(envelope, request, role)  # type: ignore[arg-type]
            needed = COMMAND_ROLES.get(command)
            if needed is None:  # a Write: by its address
                # every command but Write has its role in COMMAND_ROLES
                write = cast("WriteRequest", request)
                needed = role_to_write(write.port, write.group)
            if role >= needed:
                return self._handlers[command](envelope, request)
            return self._error(envelope, request, _E.DEVICE_INVALIDACCESS,
                               self._refusal(role, needed, request))
        except Exception:
            log.exception("handling %r failed", request)
            return self._error(envelope, request, _E.DEVICE_ERROR, "internal error; see log")

    def _refusal(self, role: Role, needed: Role, req: Any) -> str:
        """``role monitor may not write ch1.x; operator or admin may``."""
        if req.COMMAND == AdsCommand.WRITE_CONTROL:
            what = "command the ADS state (WriteControl)"
        elif needed is Role.ADMIN:
            what = "change the program store (upload, delete)"
        elif getattr(req, "group", None) == OUTPUT_AREA_GROUP:
            what = "delete files of the output area"
        else:
            what = f"write {self._target(req.port, req.group, req.offset)}"
        return f"role {role.label} may not {what}; {roles_that_may(needed)} may"

    def _target(self, port: int, group: int, offset: int) -> str:
        """The name of the object at an address, else the address (refusal messages)."""
        if group == RIG.SYM_VALUE_BY_HANDLE:
            entry = self.space.by_handle(offset)
        else:
            found = self.space.find(port, group, offset)
            entry = None if isinstance(found, tuple) else found
        if entry is not None:
            return entry.obj.name
        return f"port {port} 0x{group:x}/0x{offset:x}"

    def _reply(self, envelope: Envelope, req: Any, result: ValueResult) -> bytes:
        code, payload = result
        if code:
            return self._error(envelope, req, code, payload)
        if payload is None:  # a write: the reply carries no data
            return self._ok(envelope, req)
        return self._ok(envelope, req, payload)

    # ------------------------------------------------------------ commands

    def _read_device_info(self, envelope: Envelope, req: Any) -> Reply:
        major, minor, build = (int(p) for p in __version__.split("."))
        return self._ok(envelope, req, major, minor, build, DEVICE_NAME)

    def _store(self, port: int, group: int) -> ProgramStoreService | None:
        """The program store's service when ``port`` and ``group`` address it, else None."""
        return self.programs if group == PROGRAM_STORE_GROUP and port == CncPort.COM else None

    def _output_area(self, port: int, group: int) -> OutputService | None:
        """The output area's service when ``port`` and ``group`` address it, else None."""
        return self.outputs if group == OUTPUT_AREA_GROUP and port == CncPort.COM else None

    def _read(self, envelope: Envelope, req: ReadRequest) -> Reply:
        # The hot path: an object address goes straight to the address space.
        if req.group == PROGRAM_STORE_GROUP and (
                programs := self._store(req.port, req.group)) is not None:
            return self._reply(envelope, req, programs.read(req.offset, req.length))
        if req.group == OUTPUT_AREA_GROUP and (
                outputs := self._output_area(req.port, req.group)) is not None:
            return self._reply(envelope, req, outputs.read(req.offset, req.length))
        if req.group < _RESERVED_GROUPS:
            code, payload = self._space_read(req.port, req.group, req.offset, req.length)
        else:
            code, payload = self._read_value(req.port, req.group, req.offset, req.length)
        if code:
            if code == _E.DEVICE_INVALIDSIZE:  # a string, or PLC memory (a struct)
                other = self.backend.read_other_length(req.port, req.group, req.offset, req.length)
                if other is not None:
                    return self._reply(envelope, req, other)
            return self._error(envelope, req, code, str(payload))
        return self._ok(envelope, req, payload)

    def _write(self, envelope: Envelope, req: WriteRequest) -> Reply:
        if (programs := self._store(req.port, req.group)) is not None:
            return self._reply(envelope, req, programs.write(req.offset, req.data, envelope[0]))
        if (outputs := self._output_area(req.port, req.group)) is not None:
            return self._reply(envelope, req, outputs.write(req.offset, req.data))
        code, message, writes = self.backend.decode_writes(
            req.port, req.group, req.offset, req.data)
        if code:
            return self._error(envelope, req, code, message)
        if not writes:
            return self._ok(envelope, req)

        def finish(results: list[tuple[int, str]]) -> None:
            code, message = next((r for r in results if r[0]), (0, ""))
            if code:
                self._send(envelope, self._error(envelope, req, code, message))
            else:
                self._send(envelope, self._ok(envelope, req))

        self.backend.apply_writes(writes, finish, envelope[0])
        return None

    def _read_state(self, envelope: Envelope, req: Any) -> Reply:
        return self._ok(envelope, req, self.backend.ads_state(req.port), 0)

    def _write_control(self, envelope: Envelope, req: WriteControlRequest) -> Reply:
        control = _CONTROLS.get(req.ads_state)  # type: ignore[call-overload]
        if control is None:
            allowed = ", ".join(f"{s.value} {s.name}" for s in _CONTROLS)
            return self._error(
                envelope, req, _E.DEVICE_INVALIDDATA,
                f"ADS state {req.ads_state} cannot be commanded; use {allowed}",
            )

        def done(refusal: Refusal | None) -> None:  # cycle thread
            self._loop.call_soon_threadsafe(self._finish_control, envelope, req, refusal)

        self.kernel.submit(ControlCommand(control), done)
        return None

    def _finish_control(self, envelope: Envelope, req: Any, refusal: Refusal | None) -> None:
        if refusal is None:
            self._send(envelope, self._ok(envelope, req))
        else:
            self._send(envelope, self._error(envelope, req, refusal_code(refusal), refusal.message))

    def _add_notification(self, envelope: Envelope, req: Any) -> Reply:
        front = self._front
        return self._reply(envelope, req, self.hub.add(
            envelope, req, front.cycle_ns(req), front.notify, front.first_sample_delay_s))

    def _delete_notification(self, envelope: Envelope, req: DeleteNotificationRequest) -> Reply:
        code, message = self.hub.delete(envelope, req.handle)
        if code:
            return self._error(envelope, req, code, message)
        return self._ok(envelope, req)

    def _browse(self, envelope: Envelope, req: BrowseRequest) -> Reply:
        # The catalogue does not change while the service runs (frozen objects, added at
        # start-up): describing it once per pattern spares the event loop 10-30 ms of
        # Python per browse of ``*``, during which the realtime cycle waited for the GIL
        # up to a switch interval every cycle (issue 37, docs/kernel.md).
        found = self._browsed.get(req.pattern)
        if found is None:
            # as tuples of atoms (the same msgpack arrays): the collector stops tracking
            # them, so 50 000 kept objects do not lengthen its full collections
            found = [_as_tuples(obj.describe()) for obj in self.space.match(req.pattern)]
            if len(self._browsed) >= BROWSE_PATTERNS_KEPT:
                self._browsed.clear()  # patterns are the clients' choice: bounded
            self._browsed[req.pattern] = found
        return self._ok(envelope, req, found)

    # ------------------------------------------------------------ read-write

    def _read_write(self, envelope: Envelope, req: ReadWriteRequest, role: Role = _ADMIN) -> Reply:
        # The read length is a buffer size (TwinCAT: 0xFFFFFFFF when the client does not
        # know the size); each service answers with its data's real length.
        handler = self._read_write_groups.get(req.group)
        if handler is not None:  # a sum command
            if req.group == RIG.SUM_WRITE and role is not _ADMIN:
                return self._sum_write(envelope, req, role)
            return handler(envelope, req)
        if req.port == _SYSTEM_SERVICE and self.files is not None \
                and self.files.serves(req.group):
            return self._reply(envelope, req, self.files.read_write(
                envelope[0], req.group, req.offset, req.data, req.read_length, role))
        if (programs := self._store(req.port, req.group)) is not None:
            result = programs.read_write(req.offset, req.data, req.read_length,
                                         self._answer_later(envelope, req))
            return None if result is None else self._reply(envelope, req, result)
        if (outputs := self._output_area(req.port, req.group)) is not None:
            return self._output_download(outputs, envelope, req)
        return self._reply(envelope, req, self.backend.read_write_value(
            req.port, req.group, req.offset, req.read_length, req.data))

    def _output_download(
        self, outputs: OutputService, envelope: Envelope, req: ReadWriteRequest
    ) -> Reply:
        """A download from the output area: now, or once the writer has written what was
        queued for the file (answered then, from the writer thread through the loop)."""
        result = outputs.read_write(req.offset, req.data, req.read_length,
                                    self._answer_later(envelope, req))
        return None if result is None else self._reply(envelope, req, result)

    def _answer_later(self, envelope: Envelope, req: Any) -> Callable[[ValueResult], None]:
        """The callback that answers ``req`` from another thread, through the loop."""

        def answer(result: ValueResult) -> None:  # the writer's or the indexer's thread
            def send() -> None:
                self._send(envelope, self._reply(envelope, req, result))
            try:
                self._loop.call_soon_threadsafe(send)
            except RuntimeError:  # the loop is closed: the service stops
                pass

        return answer

    def _sum_items(
        self, req: ReadWriteRequest, decode: Callable[..., Any]
    ) -> tuple[int, Any]:
        if not 0 < req.offset <= SUM_COMMAND_MAX_ITEMS:
            return _E.DEVICE_INVALIDPARM, f"a sum command carries 1..{SUM_COMMAND_MAX_ITEMS} items"
        try:
            return 0, decode(req.offset, req.data)
        except ValueError as exc:
            return _E.DEVICE_INVALIDSIZE, str(exc)

    def _sum_read(self, envelope: Envelope, req: ReadWriteRequest) -> Reply:
        code, items = self._sum_items(req, sums.decode_sum_read)
        if code:
            return self._error(envelope, req, code, items)
        needed = 4 * len(items) + sum(i.read_length for i in items)
        if req.read_length < needed or needed > MAX_DATA_BYTES:
            return self._error(
                envelope, req, _E.DEVICE_INVALIDSIZE,
                f"sum read of these items returns {needed} bytes; read length is {req.read_length}",
            )
        read, port = self._read_value, req.port
        results = []
        for item in items:
            length = item.read_length
            code, data = read(port, item.group, item.offset, length)
            if code:
                data = bytes(length)
            elif len(data) != length:  # a service answer shorter than asked: keep the slots
                data = data[:length].ljust(length, b"\x00")
            results.append((code, data))
        return self._ok(envelope, req, sums.encode_sum_read_reply(results))

    def _sum_write(self, envelope: Envelope, req: ReadWriteRequest, role: Role = _ADMIN) -> Reply:
        code, items = self._sum_items(req, sums.decode_sum_write)
        if code:
            return self._error(envelope, req, code, items)
        codes: list[int] = [0] * len(items)
        writes: list[tuple[Entry, Any]] = []
        slots: list[int] = []  # the item of each write (a struct item makes several)
        for k, item in enumerate(items):
            if role < _ADMIN and role < role_to_write(req.port, item.group):  # admin: no call
                codes[k] = _E.DEVICE_INVALIDACCESS  # beyond the peer's role: this slot only
                continue
            code, _, item_writes = self.backend.decode_writes(
                req.port, item.group, item.offset, item.data)
            if code:
                codes[k] = code
            writes += item_writes
            slots += [k] * len(item_writes)

        def finish(results: list[tuple[int, str]]) -> None:
            for k, (code, _) in zip(slots, results):
                codes[k] = codes[k] or code
            self._send(envelope, self._ok(envelope, req, sums.encode_codes(codes)))

        self.backend.apply_writes(writes, finish, envelope[0])
        return None

    def _sum_read_write(self, envelope: Envelope, req: ReadWriteRequest) -> Reply:
        code, items = self._sum_items(req, sums.decode_sum_read_write)
        if code:
            return self._error(envelope, req, code, items)
        results = []
        for item in items:
            code, data = self.backend.read_write_value(
                req.port, item.group, item.offset, item.read_length, item.data)
            results.append((code, b"") if code else (0, data))
        reply = sums.encode_sum_read_write_reply(results)
        if len(reply) > min(req.read_length, MAX_DATA_BYTES):
            return self._error(
                envelope, req, _E.DEVICE_INVALIDSIZE,
                f"sum read-write of these items returns {len(reply)} bytes; read length is "
                f"{req.read_length} (at most {MAX_DATA_BYTES})",
            )
        return self._ok(envelope, req, reply)
