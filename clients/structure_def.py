"""pyads' ``structure_def`` of a PLC struct symbol, from the service's type information.

pyads reads and writes a struct by name (``read_structure_by_name``,
``write_structure_by_name``) with a ``structure_def``: a tuple of ``(name, PLCTYPE_...,
count)`` (``(name, PLCTYPE_STRING, count, characters)`` for a STRING, ``(name,
inner_def, count)`` for a nested struct) laid out one after the other. pyads cannot build
it from the symbol by itself (``get_symbol(name).read()`` of a struct raises inside
pyads), so ``structure_def`` builds it from what a TwinCAT code generator reads: the
symbol's entry (0xF009) and its data type with its members (0xF011), where every gap is
a padding member of its own (``_pad_0x0011 : ARRAY [0..6] OF BYTE``), so the tuple keeps
every member at its offset. ``format_structure_def`` prints it as Python to copy.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

from cnc_objects.protocol.ads_symbols import (
    AdsDataType,
    DataTypeEntry,
    SymbolGroup,
    decode_datatype_entry,
    decode_symbol_entry,
    parse_twincat_type,
)
from cnc_objects.protocol.constants import CncPort
from cnc_objects.protocol.datatypes import STRING_ENCODING

from .errors import ClientValueError

#: Read length of a symbol or data type entry (a buffer size: the entry comes back whole).
ENTRY_BUFFER_BYTES = 0x10000
# TwinCAT elementary type -> pyads constant (pyads.constants); STRING(n) apart
_PLCTYPES = {name: f"pyads.PLCTYPE_{name}" for name in (
    "BOOL", "BYTE", "WORD", "DWORD", "SINT", "USINT", "INT", "UINT", "DINT", "UDINT",
    "LINT", "ULINT", "REAL", "LREAL")}


class RawClient(Protocol):
    """What ``structure_def`` needs of a client: ADS ReadWrite (the blocking ``Client``)."""

    def read_write_raw(
        self, port: int, group: int, offset: int, data: bytes, read_length: int
    ) -> bytes:
        """ADS ReadWrite at an address: ``data`` in, up to ``read_length`` bytes out."""
        ...


@dataclass(frozen=True, slots=True)
class StructureDef:
    """The structure_defs of a symbol: ``definitions`` (type name, Python source) with
    the nested ones first, ``type_name`` the outer one; ``array_size`` the element count
    for an array of structs (pyads' ``array_size``), else 1."""

    symbol: str
    type_name: str
    size: int
    array_size: int
    definitions: tuple[tuple[str, str], ...]


def _name_bytes(name: str) -> bytes:
    try:
        return name.encode(STRING_ENCODING) + b"\x00"
    except UnicodeEncodeError:
        raise ClientValueError(f"{name!r}: a symbol name is CP1252 text") from None


def _identifier(type_name: str) -> str:
    """A Python name for a type (``ST_gpCh_spindle`` stays; other characters become _)."""
    return "".join(c if c.isalnum() or c == "_" else "_" for c in type_name)


class _Builder:
    """Fetches data types by name (each once) and writes their structure_defs."""

    def __init__(self, client: RawClient) -> None:
        self._client = client
        self._types: dict[str, DataTypeEntry] = {}
        self.definitions: dict[str, str] = {}  # type name -> source, nested first

    def type_entry(self, name: str) -> DataTypeEntry:
        if name not in self._types:
            data = self._client.read_write_raw(
                CncPort.PLC, SymbolGroup.DT_INFO_BY_NAME_EX, 0, _name_bytes(name),
                ENTRY_BUFFER_BYTES)
            self._types[name] = decode_datatype_entry(data)[0]
        return self._types[name]

    def item(self, name: str, type_name: str) -> str:
        """The tuple of one member: ``("name", TYPE, count[, characters])``."""
        count = 1
        entry: DataTypeEntry | None = None
        try:
            parse_twincat_type(type_name)
        except ValueError:
            entry = self.type_entry(type_name)
        if entry is not None and entry.array:
            if len(entry.array) != 1:
                raise ClientValueError(f"{name}: {type_name} has more than one dimension; "
                                       "a structure_def holds one")
            count = entry.array[0][1]
            type_name = entry.type_name  # the element's
        return f"({name!r}, {self.element(name, type_name)}, {count}" + self._characters(
            type_name) + ")"

    def element(self, name: str, type_name: str) -> str:
        """The pyads type of one element: a constant, or a struct's structure_def."""
        try:
            tc = parse_twincat_type(type_name)
        except ValueError:
            entry = self.type_entry(type_name)
            if entry.array or not entry.sub_items:
                raise ClientValueError(f"{name}: {type_name} is neither a struct nor an "
                                       "elementary type; a structure_def cannot hold it"
                                       ) from None
            return self.struct(entry)
        if tc.data_type == AdsDataType.STRING:
            return "pyads.PLCTYPE_STRING"
        return _PLCTYPES[tc.name]

    @staticmethod
    def _characters(type_name: str) -> str:
        try:
            tc = parse_twincat_type(type_name)
        except ValueError:
            return ""
        return f", {tc.size - 1}" if tc.data_type == AdsDataType.STRING else ""

    def struct(self, entry: DataTypeEntry) -> str:
        """The Python name of ``entry``'s structure_def, written (once) with its members'."""
        identifier = _identifier(entry.name)
        if entry.name not in self.definitions:
            items = [self.item(member.name, member.type_name) for member in entry.sub_items]
            body = "".join(f"    {item},\n" for item in items)
            self.definitions[entry.name] = f"{identifier} = (\n{body})"
        return identifier


def structure_def(client: RawClient, symbol: str) -> StructureDef:
    """The structure_def of the struct (or array of structs) ``symbol``;
    ``ClientValueError`` for a symbol of another type, the service's ``AdsError`` (0x710)
    for an unknown name."""
    data = client.read_write_raw(CncPort.PLC, SymbolGroup.INFO_BY_NAME_EX, 0,
                                 _name_bytes(symbol), ENTRY_BUFFER_BYTES)
    entry = decode_symbol_entry(data)[0]
    if entry.data_type != AdsDataType.BIGTYPE:
        try:
            pyads_type = _PLCTYPES.get(parse_twincat_type(entry.type_name).name,
                                       "pyads.PLCTYPE_STRING")
        except ValueError:
            pyads_type = entry.type_name
        raise ClientValueError(
            f"{entry.name} is {entry.type_name}, not a struct: read it with "
            f"plc.read_by_name({entry.name!r}, {pyads_type})")
    builder = _Builder(client)
    outer = builder.type_entry(entry.type_name)
    array_size = 1
    if outer.array:
        if len(outer.array) != 1:
            raise ClientValueError(f"{entry.name} is {entry.type_name}: pyads reads arrays "
                                   "of one dimension")
        array_size = outer.array[0][1]
        try:
            parse_twincat_type(outer.type_name)
        except ValueError:
            outer = builder.type_entry(outer.type_name)
        else:
            raise ClientValueError(
                f"{entry.name} is {entry.type_name}, not a struct: read it with "
                f"plc.read_by_name({entry.name!r}, {builder.element(entry.name, outer.type_name)}"
                f" * {array_size})")
    builder.struct(outer)
    return StructureDef(entry.name, outer.name, entry.size, array_size,
                        tuple(builder.definitions.items()))


def format_structure_def(found: StructureDef) -> str:
    """Python to copy: a comment naming the symbol, the structure_defs (nested first)
    and the pyads calls that use them."""
    name = _identifier(found.type_name)
    array = f", array_size={found.array_size}" if found.array_size != 1 else ""
    of = f"{found.array_size} x {found.type_name}" if array else found.type_name
    lines = [f"# {found.symbol}: {of}, {found.size} bytes (cnc ads structure-def)"]
    lines += [source for _, source in found.definitions]
    lines.append(f"# values = plc.read_structure_by_name({found.symbol!r}, {name}{array})")
    lines.append(f"# plc.write_structure_by_name({found.symbol!r}, values, {name}{array})")
    return "\n".join(lines)
