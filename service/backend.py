"""What both front ends serve: the address space, the kernel, the program store, the
symbol services and the notification hub, with the value operations they share.

One ``Backend`` per service; each front end (ZeroMQ, ADS over AMS/TCP) wraps it in a
``Dispatcher`` of its own. Everything here answers ADS codes, never raises: ``(0,
payload)`` on success, ``(code, message)`` otherwise.

A STRING object may be read with any length (the buffer cut to it); every other object
must be read with exactly its size (0x705 otherwise).

Reserved index groups served here, on every port unless noted:

- 0xF005 value by handle (the handle is the offset), 0xF006 release handle (write),
  0xF003 handle by name and 0xF004 value by name (ReadWrite with the name);
- 0xF100 device data on port 851: offset 0 the ADS state, offset 2 the device state
  (UINT each; both at once with length 4), so ADS clients can watch the PLC state;
- the symbol and data-type services (0xF008 ... 0xF011) of ``symbols``, when given.
"""

from __future__ import annotations

import asyncio
import struct
from collections.abc import Callable, Hashable
from functools import partial
from typing import Any, Protocol

from cnc_objects.objects import AddressSpace, Entry
from cnc_objects.objects.catalog import PLC_GROUP
from cnc_objects.objects.plc_structs import PlcStructs
from cnc_objects.protocol.ads_symbols import encode_handle_info, twincat_type
from cnc_objects.protocol.constants import (
    DEVICE_DATA_ADS_STATE,
    DEVICE_DATA_DEVICE_STATE,
    AdsState,
    AmsPort,
    CncPort,
)
from cnc_objects.protocol.constants import ReservedIndexGroup as RIG
from cnc_objects.protocol.datatypes import STRING_ENCODING
from cnc_objects.protocol.errors import AdsReturnCode

from .ads.file_service import FileService
from .binding import refusal_code
from .jog_holds import JOG_HOLD_TIMEOUT_S, JogHolds
from .kernel.commands import Refusal
from .kernel.kernel import Kernel
from .notifications import NotificationCounts, NotificationHub, NotificationLimits
from .output_service import OutputService
from .program_service import ProgramStoreService
from .sample_reads import Encoder, Getter, encoder_of

_E = AdsReturnCode
_U16 = struct.Struct("<H")
_U32 = struct.Struct("<I")
ValueResult = tuple[int, Any]  # (0, payload) or (code, message)


class SymbolServices(Protocol):
    """The symbol and data-type information groups (TwinCAT's 0xF008 ... 0xF011)."""

    def handles(self, group: int) -> bool:
        """True for the index groups this service answers."""
        ...

    def read(self, group: int, offset: int, length: int) -> tuple[int, bytes | str]:
        """ADS Read of ``group``: (0, data) or (code, message)."""
        ...

    def read_write(
        self, group: int, offset: int, data: bytes, read_length: int
    ) -> tuple[int, bytes | str]:
        """ADS ReadWrite of ``group``: (0, data) or (code, message)."""
        ...

    def write(self, group: int, offset: int, data: bytes) -> tuple[int, bytes | str]:
        """ADS Write of ``group``: (0, b"") or (code, message)."""
        ...


class Backend:
    """The state both front ends serve, and the value operations they share."""

    def __init__(
        self,
        space: AddressSpace,
        kernel: Kernel,
        loop: asyncio.AbstractEventLoop,
        programs: ProgramStoreService | None = None,
        symbols: SymbolServices | None = None,
        notification_limits: NotificationLimits | None = None,
        notification_counts: NotificationCounts | None = None,
        outputs: OutputService | None = None,
        structs: PlcStructs | None = None,
        jog_hold_timeout_s: float = JOG_HOLD_TIMEOUT_S,
        repeatable_samples: bool = False,
    ) -> None:
        """``notification_limits``: what notifications may hold (``[limits]``
        notifications_per_client, notifications_total, notification_max_bytes,
        notification_bytes_per_client; their defaults without); ``notification_counts``: where
        the hub keeps its counts (the address space serves them); ``outputs``: the
        output area (the files the kernel writes); ``structs``: the HLI's struct and
        array symbols, by name and by handle (none without); ``jog_hold_timeout_s``:
        a jog key not renewed for this long is released (``jog_holds``);
        ``repeatable_samples``: the hub samples every due cycle and drops nothing
        (``[clock] samples = "repeatable"``, ``NotificationHub``)."""
        self.space = space
        self.structs = structs if structs is not None else PlcStructs(AddressSpace())
        self.kernel = kernel
        self.loop = loop
        self.programs = programs
        # TwinCAT's file functions (port 10000) on the same store and its uploads
        self.files = FileService(programs.uploads) if programs is not None else None
        self.outputs = outputs
        self.symbols = symbols
        # jog keys held by their connections (the dead-man, ``jog_holds``)
        self.jog_holds = JogHolds(loop, kernel.submit, jog_hold_timeout_s)
        self.hub = NotificationHub(
            self.read_value, loop, kernel.cycle_ns, kernel.reading,
            notification_limits, notification_counts, repeatable=repeatable_samples,
            resolve=self.direct_read,
        )

    # ------------------------------------------------------------ reads

    def read_value(self, port: int, group: int, offset: int, length: int) -> ValueResult:
        """Read at an address, reserved groups included: (0, data) or (code, message)."""
        if group == RIG.SYM_VALUE_BY_HANDLE:
            entry = self.space.by_handle(offset)
            if entry is not None:
                return self.space.read_entry_buffer(entry, length)
            node = self.structs.by_handle(offset)
            if node is None:
                return _E.DEVICE_SYMBOLNOTFOUND, f"handle {offset} is unknown"
            return self.structs.read(node, length)
        if group == RIG.DEVICE_DATA and port == CncPort.PLC:
            return self._device_data(offset, length)
        symbols = self.symbols
        if symbols is not None and symbols.handles(group):
            return symbols.read(group, offset, length)
        code, data = self.space.read(port, group, offset, length)
        if code == _E.DEVICE_INVALIDSIZE:
            return self.read_other_length(port, group, offset, length) or (code, data)
        return code, data

    def direct_read(
        self, port: int, group: int, offset: int, length: int,
    ) -> tuple[Getter, Encoder] | None:
        """The getter and encoder of the object a read of this address answers whole, as
        ``read_value`` would (by address with the object's size, or by handle with at
        least its size); None for every other read (symbol services, device data, PLC
        memory ranges, a string cut to a shorter buffer). The notification hub samples
        such a subscription without the lookups of ``read_value`` (issue 37)."""
        entry: Entry | None
        if group == RIG.SYM_VALUE_BY_HANDLE:
            entry = self.space.by_handle(offset)
        elif group == RIG.DEVICE_DATA and port == CncPort.PLC:
            return None
        elif self.symbols is not None and self.symbols.handles(group):
            return None
        else:
            found = self.space.find(port, group, offset)
            entry = None if isinstance(found, tuple) else found
            if entry is not None and length != entry.obj.dtype.size:
                return None  # a cut string or a PLC memory range: read_other_length
        if entry is None or entry.read is None or length < entry.obj.dtype.size:
            return None
        return entry.read, encoder_of(entry.obj.dtype)

    def read_other_length(
        self, port: int, group: int, offset: int, length: int,
    ) -> ValueResult | None:
        """A read at an address with another length than the object's, as a TwinCAT PLC
        answers it: a STRING object gets its buffer cut to ``length`` (whole when longer;
        ADS clients read strings with a buffer of their own size, pyads 1024 characters);
        at a PLC symbol's address (port 851, 0x4020), ``length`` bytes of the PLC memory
        area (a struct, or the symbols that follow); None for any other object."""
        if port == CncPort.PLC and group == PLC_GROUP:
            return self.structs.read_memory(offset, length)
        if group == RIG.SYM_VALUE_BY_HANDLE:
            entry = self.space.by_handle(offset)
        else:
            found = self.space.find(port, group, offset)
            entry = None if isinstance(found, tuple) else found
        if entry is None or entry.obj.dtype.kind != "str":
            return None
        code, data = self.space.read_entry(entry, entry.obj.dtype.size)
        return (code, data) if code else (0, data[:length])

    def ads_state(self, port: int) -> AdsState:
        """The ADS state of a port's device: RUN while the cycle task runs, else STOP; the
        system service (port 10000) is RUN as long as the service answers at all."""
        if port == AmsPort.SYSTEM_SERVICE or self.kernel.running:
            return AdsState.RUN
        return AdsState.STOP

    def _device_data(self, offset: int, length: int) -> ValueResult:
        """ADS state and device state (UINT each) from ``offset`` on, as much of them as
        the read length holds: the length is a buffer size, as in TwinCAT."""
        state = self.ads_state(CncPort.PLC)
        if offset not in (DEVICE_DATA_ADS_STATE, DEVICE_DATA_DEVICE_STATE):
            return (_E.DEVICE_INVALIDOFFSET,
                    f"device data has offset 0 (ADS state) and 2 (device state), not {offset}")
        fields = (_U16.pack(state) + _U16.pack(0))[offset:]
        if length < 2:
            return (_E.DEVICE_INVALIDSIZE,
                    f"device data fields are UINT, 2 bytes; read asked {length}")
        return 0, fields[: 2 * min(length // 2, len(fields) // 2)]

    def read_write_value(
        self, port: int, group: int, offset: int, read_length: int, data: bytes
    ) -> ValueResult:
        """ReadWrite at one address: handle by name, value by name, the symbol services;
        object addresses take Read or Write only."""
        if group in (RIG.SYM_HANDLE_BY_NAME, RIG.SYM_VALUE_BY_NAME):
            try:
                name = data.split(b"\x00", 1)[0].decode(STRING_ENCODING)
            except UnicodeDecodeError:
                return _E.DEVICE_INVALIDDATA, "a symbol name must be CP1252 text"
            entry = self.space.by_name(name)
            if entry is None:
                return self._struct_by_name(group, name, read_length)
            if group == RIG.SYM_VALUE_BY_NAME:
                return self.space.read_entry_buffer(entry, read_length)
            tc = twincat_type(entry.obj.dtype)
            return _handle_answer(entry.handle, tc.size, tc.name, read_length)
        symbols = self.symbols
        if symbols is not None and symbols.handles(group):
            return symbols.read_write(group, offset, data, read_length)
        found = self.space.find(port, group, offset)
        if isinstance(found, tuple):
            return found
        if not data:  # a ReadWrite that writes nothing reads, the length a buffer size
            return self.space.read_entry_buffer(found, read_length)
        return (_E.DEVICE_SRVNOTSUPP,
                f"{found.obj.name} takes ReadWrite without data (a read); write with Write")

    def _struct_by_name(self, group: int, name: str, read_length: int) -> ValueResult:
        """Handle or value of a struct or array symbol (``gpCh[0].contour_lookahead``)."""
        node = self.structs.by_name(name)
        if node is None:
            return _E.DEVICE_SYMBOLNOTFOUND, f"no object is named {name!r}"
        if group == RIG.SYM_VALUE_BY_NAME:
            return self.structs.read(node, read_length)
        return _handle_answer(node.handle, node.size, node.type_name, read_length)

    # ------------------------------------------------------------ writes

    def decode_writes(
        self, port: int, group: int, offset: int, data: bytes
    ) -> tuple[int, str, list[tuple[Entry, Any]]]:
        """(0, "", [(entry, value), ...]): the object writes a Write makes (none for a
        handle release or a struct written with what it holds, one per changed member
        of a struct), or (code, message, [])."""
        if group == RIG.SYM_VALUE_BY_HANDLE:
            entry = self.space.by_handle(offset)
            if entry is not None:
                return _one(self.space.decode_entry_write(entry, data))
            node = self.structs.by_handle(offset)
            if node is None:
                return _E.DEVICE_SYMBOLNOTFOUND, f"handle {offset} is unknown", []
            return self.structs.decode_write(node, data)
        if group == RIG.SYM_RELEASE_HANDLE:
            if len(data) != 4:
                return _E.DEVICE_INVALIDSIZE, "release a handle by writing its 4 bytes", []
            handle = _U32.unpack(data)[0]
            if self.space.by_handle(handle) is None and self.structs.by_handle(handle) is None:
                return _E.DEVICE_SYMBOLNOTFOUND, f"handle {handle} is unknown", []
            return 0, "", []  # handles are stable per object: nothing to free
        if group == RIG.DEVICE_DATA and port == CncPort.PLC:
            return (_E.DEVICE_INVALIDACCESS,
                    "device data is read-only; change the state with WriteControl", [])
        symbols = self.symbols
        if symbols is not None and symbols.handles(group):
            code, message = symbols.write(group, offset, data)
            return (code, str(message), []) if code else (0, "", [])
        decoded = self.space.decode_write(port, group, offset, data)
        if decoded[0] and port == CncPort.PLC and group == PLC_GROUP and (
            decoded[0] == _E.DEVICE_INVALIDSIZE
            or (decoded[0] == _E.DEVICE_INVALIDACCESS
                and self.structs.is_symbol_range(offset, len(data)))
        ):  # a struct at its address, whose first member may be read-only (issue 41)
            return self.structs.decode_memory_write(offset, data)
        return _one(decoded)

    def connection_ended(self, holder: Hashable, how: str) -> None:
        """A front end's connection ``holder`` is gone: the jog keys it holds are
        released (``jog_holds``), its program upload in chunks is abandoned, the files it
        opened with FOPEN are closed (a write among them abandoned)."""
        self.jog_holds.ended(holder, how)
        if self.programs is not None:
            self.programs.uploads.connection_ended(holder)
        if self.files is not None:
            self.files.connection_ended(holder)

    def apply_writes(
        self, items: list[tuple[Entry, Any]], finish: Callable[[list[tuple[int, str]]], None],
        holder: Hashable = None,
    ) -> None:
        """Queue the writes for the kernel; ``finish`` gets (code, message) per item on the
        loop once the cycle thread has applied all of them. ``holder``: the connection
        that writes (a jog key it presses is held by it, ``jog_holds``)."""
        results: list[tuple[int, str]] = [(0, "")] * len(items)
        remaining = [len(items)]
        if not items:
            finish(results)
            return
        loop = self.loop
        if any(entry.written is not None for entry, _ in items):
            finish = _telling_written(items, finish)

        def applied(k: int, refusal: Refusal | None) -> None:  # runs on the cycle thread
            if refusal is not None:
                results[k] = (refusal_code(refusal), refusal.message)
            remaining[0] -= 1
            if remaining[0] == 0:
                loop.call_soon_threadsafe(finish, results)

        holds = self.jog_holds
        for k, (entry, value) in enumerate(items):
            assert entry.write is not None  # decode_writes gives writable entries only
            if holds.is_held(entry):  # before the kernel has it: a release comes after
                holds.written(holder, entry, value)
            self.kernel.submit(entry.write(value), partial(applied, k))


def _telling_written(
    items: list[tuple[Entry, Any]], finish: Callable[[list[tuple[int, str]]], None]
) -> Callable[[list[tuple[int, str]]], None]:
    """``finish`` that first tells each entry that keeps its writes (a command object
    reading back its last value) the value the kernel applied; refused ones are not."""

    def told(results: list[tuple[int, str]]) -> None:
        for (entry, value), (code, _) in zip(items, results):
            if code == 0 and entry.written is not None:
                entry.written(value)
        finish(results)

    return told


def _one(decoded: tuple[int, Any, Any]) -> tuple[int, str, list[tuple[Entry, Any]]]:
    """An address-space write decoding as ``decode_writes`` answers it."""
    code, target, value = decoded
    return (code, target, []) if code else (0, "", [(target, value)])


def _handle_answer(handle: int, size: int, type_name: str, read_length: int) -> ValueResult:
    """Handle by name: the handle alone for a 4-byte buffer (pyads, AdsLib), TwinCAT 3's
    extended answer (handle, size, type name) when the buffer holds it (ads-client asks
    with 0xFFFFFFFF, 0xFFFF per sum item)."""
    extended = encode_handle_info(handle, size, type_name)
    if read_length >= len(extended):
        return 0, extended
    if read_length >= 4:
        return 0, _U32.pack(handle)
    return _E.DEVICE_INVALIDSIZE, f"a handle is 4 bytes; read length is {read_length}"
