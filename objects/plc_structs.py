"""The HLI hierarchy as a PLC's symbol table has it: structs and arrays over the PLC symbols.

The PLC symbols (port 851) are the leaves of ISG's HLI structures, named by their ST
path without ``^`` (``gpCh[0].contour_lookahead.request.length``). Every prefix of such
a path is a symbol of its own, as in a TwinCAT PLC: ``gpCh`` (an array of the channel
structs), ``gpCh[0]`` (a struct), ``gpCh[0].contour_lookahead`` (a struct), ...,
``gpCh[0].contour_lookahead.response.block`` (an array). Their layout is the leaves'
own: a struct starts at its first member and ends with its last, an array element
takes the stride between elements (so the array is contiguous, as in PLC memory), and
the bytes between members are padding, read as zeros. Members never overlap and come
in ascending offsets, as a compiler lays a struct out (a layout that would overlap is
refused when the structs are built); ``struct_members`` names the padding as members of
its own (``_pad_0x0004 : ARRAY [0..11] OF BYTE``, the offset in the struct), so that a
reader that lays members out one after the other (pyads' ``structure_def``, a code
generator over the type upload) finds every member where it is.

The PLC memory area is read as a PLC reads it: from where a symbol starts, any number of
bytes up to the area's end, the symbols in the range at their offsets and zeros between
them; so a struct at its own address (its first member's offset) reads as a struct. A
struct or array is written member by member, at its address or by handle (the same
rule both ways): the writable members whose bytes change are written; padding is
ignored; the bytes of read-only members are ignored too when a member of the struct is
writable, and must be the bytes it holds when none is (``decode_memory_write`` says
why). ``handle`` numbers start at ``HANDLE_BASE``, apart from the address space's.

Type names: ISG's where its HLI documentation names the type (reference/cnc-objects.md
section 6: HLI_CONTOUR_LOOKAHEAD, MC_CONTROL_BOOL_UNIT, ...), else ``ST_`` and the path
without indices (``ST_gpCh_bahn_state``); arrays ``ARRAY [0..31] OF <element type>``.
"""

from __future__ import annotations

import bisect
import re
from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Any

from cnc_objects.protocol.ads_symbols import twincat_type
from cnc_objects.protocol.constants import CncPort
from cnc_objects.protocol.errors import AdsReturnCode

from .address_space import AddressSpace, Entry, name_key

_E = AdsReturnCode
#: First handle of a struct or array symbol (the address space's handles are 1..N).
HANDLE_BASE = 0x4000_0000
#: Name of the padding member at ``offset`` in its struct (``struct_members``).
PADDING_NAME = "_pad_0x{offset:04x}"
#: Type of a padding member of ``size`` bytes.
PADDING_TYPE = "ARRAY [0..{last}] OF BYTE"
_PART = re.compile(r"^([^\[\]]+)\[(\d+)\]$")

#: Type names of ISG's HLI (by path without indices, below the root array's element).
HLI_TYPE_NAMES: dict[str, str] = {
    "gpCh[]": "HLI_CHANNEL",
    "gpAx[]": "HLI_AXIS",
    "pMC[]": "MC_CHANNEL",
    "gpCh[].contour_lookahead": "HLI_CONTOUR_LOOKAHEAD",
    "gpCh[].contour_lookahead.request": "HLI_CONTOUR_LOOKAHEAD_REQUEST",
    "gpCh[].contour_lookahead.response": "HLI_CONTOUR_LOOKAHEAD_RESPONSE",
    "gpCh[].contour_lookahead.response.block[]": "HLI_CONTOUR_LOOKAHEAD_BLOCK",
    "gpCh[].contour_lookahead.state": "HLI_CONTOUR_LOOKAHEAD_STATE",
    "gpCh[].bahn_mc_control.suspend_axis_output": "MC_CONTROL_BOOL_UNIT",
    "gpCh[].decoder_mc_control.execution_mode": "MC_CONTROL_SGN32_UNIT",
}


@dataclass(eq=False)
class Node:
    """A symbol of the hierarchy: a leaf (``entry``), a struct (``members``) or an array
    (``elements``, ``lower_bound`` 0). ``start`` is the absolute offset in the PLC
    memory area, ``size`` in bytes; ``type_name`` the TwinCAT type of a struct or array."""

    name: str
    type_path: str
    entry: Entry | None = None
    members: dict[str, Node] = field(default_factory=dict)
    elements: dict[int, Node] = field(default_factory=dict)
    start: int = 0
    size: int = 0
    type_name: str = ""
    handle: int = 0
    leaves: tuple[tuple[Entry, int], ...] = ()  # every leaf below, at its offset in here

    @property
    def is_array(self) -> bool:
        """True for an array symbol."""
        return bool(self.elements)

    @property
    def writable(self) -> bool:
        """True when a member below may be written."""
        return any(entry.write is not None for entry, _ in self.leaves)

    def children(self) -> list[tuple[str, Node]]:
        """(member name, node) of a struct, ("[k]", node) of an array, in offset order."""
        if self.elements:
            return [(f"[{k}]", node) for k, node in sorted(self.elements.items())]
        return sorted(self.members.items(), key=lambda item: (item[1].start, item[0]))


@dataclass(frozen=True, slots=True)
class Member:
    """A member of a struct's type as ``struct_members`` lists it: ``offset`` in the
    struct, ``size`` in bytes; ``node`` the member's symbol, None for padding."""

    name: str
    offset: int
    size: int
    node: Node | None

    @property
    def type_name(self) -> str:
        """The member's TwinCAT type: the leaf's, the struct's or array's, or the padding's."""
        if self.node is None:
            return padding_type(self.size)
        if self.node.entry is not None:
            return twincat_type(self.node.entry.obj.dtype).name
        return self.node.type_name


def padding_type(size: int) -> str:
    """The type of ``size`` bytes of padding (``ARRAY [0..11] OF BYTE``)."""
    return PADDING_TYPE.format(last=size - 1)


def struct_members(node: Node) -> tuple[Member, ...]:
    """The members of the struct ``node`` in ascending offsets, with a padding member
    for every gap (the trailing one up to the struct's size included): their sizes add
    up to the struct's."""
    members: list[Member] = []
    at = 0
    for name, child in node.children():
        offset = child.start - node.start
        if offset > at:
            members.append(Member(PADDING_NAME.format(offset=at), at, offset - at, None))
        members.append(Member(name, offset, child.size, child))
        at = offset + child.size
    if node.size > at:
        members.append(Member(PADDING_NAME.format(offset=at), at, node.size - at, None))
    return tuple(members)


def _parts(name: str) -> Iterator[tuple[str, int | None]]:
    """``gpCh[0].a.b[3].c`` -> (gpCh, 0), (a, None), (b, 3), (c, None)."""
    for part in name.split("."):
        match = _PART.match(part)
        yield (match.group(1), int(match.group(2))) if match else (part, None)


class PlcStructs:
    """Struct and array symbols over the PLC leaves of an address space."""

    def __init__(self, space: AddressSpace) -> None:
        self.roots: dict[str, Node] = {}
        for obj in space.objects():
            if obj.port == CncPort.PLC:
                self._insert(space.by_name(obj.name))  # type: ignore[arg-type]
        self.symbols: list[Node] = []
        for root in self.roots.values():
            self._layout(root)
        for root in self.roots.values():
            self._collect(root)
        self._by_name = {name_key(node.name): node for node in self.symbols}
        for k, node in enumerate(self.symbols):
            node.handle = HANDLE_BASE + k
        # The PLC memory area: every leaf by its offset, where symbols start, its end.
        leaves = sorted((e.obj.offset, e.handle, e) for root in self.roots.values()
                        for e, _ in _leaves(root))
        self._leaf_starts = [start for start, _, _ in leaves]
        self._leaf_entries = [entry for _, _, entry in leaves]
        self._widest_leaf = max((e.obj.dtype.size for e in self._leaf_entries), default=0)
        self._symbol_starts = set(self._leaf_starts) | {n.start for n in self.symbols}
        self.memory_end = max((n.start + n.size for n in self.roots.values()), default=0)
        self._node_ranges = {(n.start, n.size) for n in self.symbols}

    # ------------------------------------------------------------------ building

    def _insert(self, entry: Entry) -> None:
        siblings, path, type_path = self.roots, "", ""
        parts = list(_parts(entry.obj.name))
        node: Node | None = None
        for depth, (part, index) in enumerate(parts):
            path = f"{path}.{part}" if path else part
            type_path = f"{type_path}.{part}" if type_path else part
            node = siblings.get(part)
            if node is None:
                node = siblings[part] = Node(path, type_path)
            if index is not None:  # an array: go on in its element
                path, type_path = f"{path}[{index}]", f"{type_path}[]"
                array = node
                node = array.elements.get(index)
                if node is None:
                    node = array.elements[index] = Node(path, type_path)
            if depth == len(parts) - 1:
                node.entry = entry
                node.start, node.size = entry.obj.offset, entry.obj.dtype.size
            siblings = node.members

    def _layout(self, node: Node) -> None:
        """Start and size of ``node`` and below; the types' names."""
        if node.entry is not None:
            return
        children = [child for _, child in node.children()]
        for child in children:
            self._layout(child)
        if node.elements:
            ordered = [node.elements[k] for k in sorted(node.elements)]
            span = max(child.size for child in ordered)
            starts = [child.start for child in ordered]
            strides = {b - a for a, b in zip(starts, starts[1:])}
            stride = strides.pop() if len(strides) == 1 else span
            leaf = ordered[0].entry
            if strides or stride < span or (leaf is not None and stride != span):
                raise ValueError(f"the elements of {node.name} are not evenly laid out")
            for child in ordered:
                child.size = stride  # padding up to the next element, as in PLC memory
            node.start, node.size = starts[0], stride * len(ordered)
            element = twincat_type(leaf.obj.dtype).name if leaf else ordered[0].type_name
            node.type_name = f"ARRAY [{min(node.elements)}..{max(node.elements)}] OF {element}"
            return
        node.start = min(child.start for child in children)
        node.size = max(child.start + child.size for child in children) - node.start
        ordered = [child for _, child in node.children()]  # by offset, now they are laid out
        for before, after in zip(ordered, ordered[1:]):
            if before.start + before.size > after.start:
                raise ValueError(
                    f"{before.name} (0x{before.start:x}, {before.size} bytes) overlaps "
                    f"{after.name} (0x{after.start:x}): no PLC struct can hold both")
        node.type_name = HLI_TYPE_NAMES.get(
            node.type_path, "ST_" + node.type_path.replace("[]", "").replace(".", "_"))

    def _collect(self, node: Node) -> None:
        """Every struct and array below ``node`` in ``symbols``, with its leaves."""
        if node.entry is not None:
            return
        node.leaves = tuple((entry, offset - node.start) for entry, offset in _leaves(node))
        self.symbols.append(node)
        for _, child in node.children():
            self._collect(child)

    # ------------------------------------------------------------------ lookup

    def by_name(self, name: str) -> Node | None:
        """The struct or array named ``name`` (case-insensitive, ``^`` as ``name_key`` takes it)."""
        return self._by_name.get(name_key(name))

    def by_handle(self, handle: int) -> Node | None:
        """The struct or array of ``handle``."""
        k = handle - HANDLE_BASE
        return self.symbols[k] if 0 <= k < len(self.symbols) else None

    # ------------------------------------------------------------------ values

    def read(self, node: Node, length: int) -> tuple[int, bytes | str]:
        """The bytes of ``node`` into a buffer of ``length``: its memory, members at
        their offsets; (code, message) when the buffer is too small or a member cannot
        be read."""
        if length < node.size:
            return (_E.DEVICE_INVALIDSIZE,
                    f"{node.name} is {node.type_name}, {node.size} bytes; read length is {length}")
        return self.read_memory(node.start, node.size)

    def decode_write(self, node: Node, data: bytes) -> tuple[int, str, list[tuple[Entry, Any]]]:
        """The member writes that a write of ``data`` to ``node`` makes (see
        ``decode_memory_write``); a write of another size than the node's is 0x705."""
        if len(data) != node.size:
            return (_E.DEVICE_INVALIDSIZE,
                    f"{node.name} is {node.type_name}, {node.size} bytes; write sent {len(data)}",
                    [])
        return self.decode_memory_write(node.start, data)

    # ------------------------------------------------------------------ memory

    def _overlapping(self, offset: int, length: int) -> Iterator[tuple[Entry, int]]:
        """(entry, start) of the leaves that overlap ``[offset, offset + length)``."""
        k = bisect.bisect_left(self._leaf_starts, offset - self._widest_leaf + 1)
        end = offset + length
        while k < len(self._leaf_starts) and self._leaf_starts[k] < end:
            entry = self._leaf_entries[k]
            if self._leaf_starts[k] + entry.obj.dtype.size > offset:
                yield entry, self._leaf_starts[k]
            k += 1

    def _range_refusal(self, offset: int, length: int) -> tuple[int, str] | None:
        if offset not in self._symbol_starts:
            return (_E.DEVICE_INVALIDOFFSET,
                    f"index offset 0x{offset:x} is not where a PLC symbol starts")
        if length == 0 or offset + length > self.memory_end:
            return (_E.DEVICE_INVALIDSIZE,
                    f"{length} bytes from 0x{offset:x} leave the PLC memory area "
                    f"(it ends at 0x{self.memory_end:x})")
        return None

    def read_memory(self, offset: int, length: int) -> tuple[int, bytes | str]:
        """``length`` bytes of the PLC memory area from ``offset`` (where a symbol starts),
        as a TwinCAT PLC reads its memory: the symbols in the range at their offsets,
        zeros between them."""
        refused = self._range_refusal(offset, length)
        if refused:
            return refused
        image = bytearray(length)
        for entry, start in self._overlapping(offset, length):
            code, data = AddressSpace.read_entry(entry, entry.obj.dtype.size)
            if code or not isinstance(data, bytes):  # code 0 carries the bytes
                return code, data
            lo, hi = max(start, offset), min(start + len(data), offset + length)
            image[lo - offset : hi - offset] = data[lo - start : hi - start]
        return 0, bytes(image)

    def is_symbol_range(self, offset: int, length: int) -> bool:
        """True when ``[offset, offset + length)`` is exactly a struct or array symbol."""
        return (offset, length) in self._node_ranges

    def decode_memory_write(self, offset: int, data: bytes) -> tuple[int, str, list[tuple[Entry, Any]]]:
        """The member writes that writing ``data`` into the PLC memory area at ``offset``
        makes, where the range is exactly a struct or array symbol: each writable member
        whose bytes differ from its value now; (code, message, []) and nothing written
        for a range that is not one symbol (a wrong size stays a clear 0x705, where a
        PLC would write into the neighbours) or a value a member refuses.

        The other bytes, as TwinCAT's %M memory takes a struct byte for byte: padding
        is ignored. The bytes of read-only members are ignored when the struct has a
        writable member: a client writes such a struct to change its writable members,
        with the bytes it read before (ads-client merges ``{"override_w": 500}`` into the
        struct it reads, pyads ``write_structure_by_name`` sends a whole dict), and the
        CNC changes its status members every cycle, so a rule that wanted them unchanged
        would refuse such writes at random; the CNC owns them (in a TwinCAT PLC the CNC
        overwrites them in its next cycle), so they never change kernel state. A struct
        with no writable member takes its own bytes back (a round trip changes nothing)
        and refuses other bytes 0x704 as a read-only symbol does: such a write could
        change nothing, and the client is told so."""
        refused = self._range_refusal(offset, len(data))
        if refused:
            return (*refused, [])
        if (offset, len(data)) not in self._node_ranges:
            return (_E.DEVICE_INVALIDSIZE,
                    f"a write at 0x{offset:x} covers one symbol; none there is {len(data)} bytes",
                    [])
        code, now = self.read_memory(offset, len(data))
        if code or not isinstance(now, bytes):  # code 0 carries the bytes
            return code, str(now), []
        writes: list[tuple[Entry, Any]] = []
        read_only_changed: Entry | None = None
        writable = False
        for entry, start in self._overlapping(offset, len(data)):
            size = entry.obj.dtype.size
            if start < offset or start + size > offset + len(data):
                return (_E.DEVICE_INVALIDSIZE,
                        f"a write from 0x{offset:x} of {len(data)} bytes cuts {entry.obj.name}", [])
            part = data[start - offset : start - offset + size]
            unchanged = part == now[start - offset : start - offset + size]
            if entry.write is None:
                if not unchanged and read_only_changed is None:
                    read_only_changed = entry
                continue
            writable = True
            if unchanged:
                continue
            code, target, value = AddressSpace.decode_entry_write(entry, part)
            if code:
                return code, str(target), []
            writes.append((entry, value))
        if not writable and read_only_changed is not None:
            return (_E.DEVICE_INVALIDACCESS,
                    f"nothing from 0x{offset:x} on may be written ({read_only_changed.obj.name} "
                    "is read-only); only the bytes it holds are taken back", [])
        return 0, "", writes

def _leaves(node: Node) -> Iterator[tuple[Entry, int]]:
    """(entry, absolute offset) of every leaf below ``node``."""
    if node.entry is not None:
        yield node.entry, node.start
        return
    for _, child in node.children():
        yield from _leaves(child)
