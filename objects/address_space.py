"""The address space: find an object by address, name, handle or pattern; read and decode.

Each entry points at live state through a getter and a setter that whoever builds the
space supplies (the service binds them to the kernel). Reads and write-decoding return
an ADS code, never raise: ``(0, data)`` on success, ``(code, message)`` otherwise, so
the message layer answers with the code and a sentence that says why.
"""

from __future__ import annotations

import fnmatch
import logging
import re
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import Any, Protocol

from cnc_objects.protocol.errors import AdsReturnCode

from .model import CncObject

log = logging.getLogger(__name__)

Getter = Callable[[], Any]
Setter = Callable[[Any], Any]

_E = AdsReturnCode


@dataclass(slots=True)
class Entry:
    """An object with its bindings. ``handle`` is stable for the life of the space."""

    obj: CncObject
    handle: int
    read: Getter | None
    write: Setter | None
    #: Told each value once the write is applied (a command object keeps it to read back).
    written: Callable[[Any], None] | None = None


class GroupHandler(Protocol):
    """A whole index group served by code instead of objects (the COM directory)."""

    def read(self, offset: int, length: int) -> tuple[int, bytes | str]:
        """ADS read: (0, data) or (code, message)."""
        ...


_INDEX = re.compile(r"\[\d+\]")


#: A pointer dereference where ISG's HLI has its pointers: right after the element of a
#: root array (``gpCh[0]^``, ``gpAx[3]^``, ``pMC[1]^``), at the end or before a member.
_DEREFERENCE = re.compile(r"^([^.\[\]^]+\[\d+\])\^(?=\.|$)")


def name_key(name: str) -> str:
    """The key a name is looked up by: case-insensitive, as TwinCAT's symbol names, and
    without the ``^`` of a pointer dereference, since ISG's HLI documentation writes
    paths through the pointers (``gpCh[0]^.bahn_mc_control``) and the symbols are named
    without them (``gpCh[0].bahn_mc_control``). TwinCAT takes ``^`` only after a
    pointer, so only there: a ``^`` anywhere else (``gpCh^[0]``, ``gpCh[0].spindle^``)
    stays in the key, which no symbol has (0x710, as for an unknown name)."""
    key = name.lower()
    if "^" in key:
        match = _DEREFERENCE.match(key)
        if match is not None:  # one ^ after the root element: drop it
            key = key[: match.end(1)] + key[match.end(1) + 1 :]
    return key


def _glob(pattern: str) -> re.Pattern[str]:
    """A regex for a glob: ``*``, ``?`` and ``[...]`` classes as in fnmatch, except that
    a bracketed number (``[0]``) is literal, as the index in a PLC name.

    ``fnmatch.translate`` does the translation: it folds runs of ``*`` and matches the
    text between stars without backtracking into earlier stars, so a pattern of many
    stars costs linear time instead of stalling the event loop (a hand-made ``.*`` per
    star took minutes for twelve stars)."""
    literal_indices = _INDEX.sub(lambda m: "[[]" + m.group()[1:], pattern)
    return re.compile(fnmatch.translate(literal_indices))


class AddressSpace:
    """Objects by (port, group, offset), by case-insensitive name and by handle."""

    def __init__(self) -> None:
        self._by_address: dict[tuple[int, int, int], Entry] = {}
        self._by_name: dict[str, Entry] = {}
        self._entries: list[Entry] = []
        self._groups: set[tuple[int, int]] = set()
        self._handlers: dict[tuple[int, int], GroupHandler] = {}
        self._ports: set[int] = set()

    # ----------------------------------------------------------------- building

    def add(
        self,
        obj: CncObject,
        read: Getter | None = None,
        write: Setter | None = None,
        aliases: Iterable[int] = (),
        written: Callable[[Any], None] | None = None,
    ) -> Entry:
        """Register ``obj``; ``aliases`` are other groups that address it (index-based);
        ``written`` is told each value written once the write has been applied."""
        key = obj.name.lower()
        if key in self._by_name:
            raise ValueError(f"object {obj.name} is registered twice")
        if obj.access.readable and read is None:
            raise ValueError(f"readable object {obj.name} needs a getter")
        if obj.access.writable and write is None:
            raise ValueError(f"writable object {obj.name} needs a setter")
        addresses = [(obj.port, group, obj.offset) for group in (obj.group, *aliases)]
        for address in addresses:  # check all before changing anything
            if address in self._by_address:
                other = self._by_address[address].obj.name
                raise ValueError(f"{obj.name} and {other} share address {address}")
        entry = Entry(obj, len(self._entries) + 1, read, write, written)
        for address in addresses:
            self._by_address[address] = entry
            self._groups.add(address[:2])
        self._ports.add(obj.port)
        self._by_name[key] = entry
        self._entries.append(entry)
        return entry

    def add_group(self, port: int, group: int, handler: GroupHandler) -> None:
        """Serve every offset of ``group`` on ``port`` by ``handler``."""
        self._handlers[(port, group)] = handler
        self._groups.add((port, group))
        self._ports.add(port)

    # ----------------------------------------------------------------- lookup

    def __len__(self) -> int:
        return len(self._entries)

    @property
    def ports(self) -> frozenset[int]:
        """Ports that serve at least one object."""
        return frozenset(self._ports)

    def objects(self) -> list[CncObject]:
        """Every object, in registration order."""
        return [e.obj for e in self._entries]

    def by_name(self, name: str) -> Entry | None:
        """The entry named ``name`` (case-insensitive, ``^`` after a root element ignored:
        ``name_key``), or None."""
        return self._by_name.get(name_key(name))

    def by_handle(self, handle: int) -> Entry | None:
        """The entry whose handle is ``handle``, or None."""
        if 0 < handle <= len(self._entries):
            return self._entries[handle - 1]
        return None

    def find(self, port: int, group: int, offset: int) -> Entry | tuple[int, str]:
        """The entry at an address, or (code, message): 0x6 port, 0x702 group, 0x703 offset."""
        entry = self._by_address.get((port, group, offset))
        if entry is not None:
            return entry
        return self._miss(port, group, offset)

    def _miss(self, port: int, group: int, offset: int) -> tuple[int, str]:
        if port not in self._ports:
            return _E.TARGETPORTNOTFOUND, f"no CNC task listens on port {port}"
        if (port, group) not in self._groups:
            return _E.DEVICE_INVALIDGRP, f"index group 0x{group:x} is unknown on port {port}"
        return (
            _E.DEVICE_INVALIDOFFSET,
            f"index offset 0x{offset:x} is unknown in group 0x{group:x} on port {port}",
        )

    def match(self, pattern: str) -> list[CncObject]:
        """Objects whose name matches the glob ``pattern`` (case-insensitive); a
        bracketed number is literal, as PLC names carry indices (``gpCh[0].*``)."""
        if pattern in ("", "*"):
            return self.objects()
        regex = _glob(pattern.lower())
        return [e.obj for e in self._entries if regex.match(e.obj.name.lower())]

    # ----------------------------------------------------------------- values

    def read(self, port: int, group: int, offset: int, length: int) -> tuple[int, bytes | str]:
        """ADS read at an address: (0, data) or (code, message)."""
        entry = self._by_address.get((port, group, offset))
        if entry is None:
            handler = self._handlers.get((port, group))
            if handler is not None:
                return handler.read(offset, length)
            return self._miss(port, group, offset)
        return self.read_entry(entry, length)

    @staticmethod
    def read_entry(entry: Entry, length: int) -> tuple[int, bytes | str]:
        """Read ``entry`` with a read length of ``length`` bytes."""
        getter, dtype = entry.read, entry.obj.dtype
        if getter is not None and length == dtype.size:
            try:
                value = getter()
                if dtype.kind == "str":  # a text of the CNC's own is made to fit, not refused
                    return 0, dtype.encode_fitted(value)
                return 0, dtype.encode(value)
            except Exception:  # a getter fault must not take the service down
                log.exception("reading %s failed", entry.obj.name)
                return _E.DEVICE_ERROR, f"reading {entry.obj.name} failed inside the service"
        if getter is None:
            return _E.DEVICE_INVALIDACCESS, f"{entry.obj.name} is write-only"
        return (
            _E.DEVICE_INVALIDSIZE,
            f"{entry.obj.name} is {dtype.name}, {dtype.size} bytes; read asked {length}",
        )

    @classmethod
    def read_entry_buffer(cls, entry: Entry, length: int) -> tuple[int, bytes | str]:
        """Read ``entry`` into a buffer of ``length`` bytes, as TwinCAT answers a read by
        handle or by name: a buffer at least the value's size gets the value (its own
        size, however large the buffer: clients that do not know the size send
        0xFFFFFFFF), a smaller one 0x705, except a STRING, whose buffer is cut to it."""
        size = entry.obj.dtype.size
        if length >= size:
            return cls.read_entry(entry, size)
        if entry.obj.dtype.kind == "str":
            code, data = cls.read_entry(entry, size)
            return (code, data) if code else (0, data[:length])
        return cls.read_entry(entry, length)  # the 0x705 that names the size

    def decode_write(
        self, port: int, group: int, offset: int, data: bytes
    ) -> tuple[int, Entry | str, Any]:
        """Check and decode an ADS write: (0, entry, value) or (code, message, None)."""
        found = self.find(port, group, offset)
        if isinstance(found, tuple):
            if (port, group) in self._handlers:
                return _E.DEVICE_INVALIDACCESS, f"index group 0x{group:x} is read-only", None
            return found[0], found[1], None
        return self.decode_entry_write(found, data)

    @staticmethod
    def decode_entry_write(entry: Entry, data: bytes) -> tuple[int, Entry | str, Any]:
        """Check and decode a write of ``data`` to ``entry``."""
        obj = entry.obj
        dtype = obj.dtype
        if entry.write is None:
            return _E.DEVICE_INVALIDACCESS, f"{obj.name} is read-only", None
        if dtype.kind == "str":
            # ADS clients commonly send a string without its padding: accept up to the
            # buffer size, padded with NUL.
            if len(data) > dtype.size:
                return (
                    _E.DEVICE_INVALIDSIZE,
                    f"{obj.name} is {dtype.name}; {len(data)} bytes do not fit",
                    None,
                )
            if len(data) == dtype.size and b"\x00" not in data:
                return (
                    _E.DEVICE_INVALIDSIZE,
                    f"{obj.name} is {dtype.name}: at most {dtype.size - 1} characters and a NUL",
                    None,
                )
            data = data.ljust(dtype.size, b"\x00")
        elif len(data) != dtype.size:
            return (
                _E.DEVICE_INVALIDSIZE,
                f"{obj.name} is {dtype.name}, {dtype.size} bytes; write sent {len(data)}",
                None,
            )
        try:
            value = dtype.decode(data)
        except (ValueError, UnicodeDecodeError) as exc:
            return _E.DEVICE_INVALIDDATA, f"{obj.name}: {exc}", None
        if dtype.kind == "bool" and data not in (b"\x00", b"\x01"):
            return _E.DEVICE_INVALIDDATA, f"{obj.name} is BOOLEAN: write 0 or 1", None
        return 0, entry, value
