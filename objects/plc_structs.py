"""The HLI hierarchy as a PLC's symbol table has it: structs and arrays over the PLC symbols.

The PLC symbols (port 851) are the leaves of ISG's HLI structures, named by their ST
path without ``^`` (``gpCh[0].contour_lookahead.request.length``). Every prefix of such
a path is a symbol of its own, as in a TwinCAT PLC: ``gpCh`` (an array of the channel
structs), ``gpCh[0]`` (a struct), ``gpCh[0].contour_lookahead`` (a struct), ...,
``gpCh[0].contour_lookahead.response.block`` (an array). Their layout is the leaves'
own: a struct starts at its first member and ends with its last, an array element
takes the stride between elements (so the array is contiguous, as in PLC memory), and
the bytes between members are padding, read as zeros.

A struct or array is read as the bytes of its members at their offsets, written member
by member (only the writable members whose bytes change; the others are left as they
are), and is reached by handle: ``handle`` numbers start at ``HANDLE_BASE``, apart from
the address space's.

Type names: ISG's where its HLI documentation names the type (reference/cnc-objects.md
section 6: HLI_CONTOUR_LOOKAHEAD, MC_CONTROL_BOOL_UNIT, ...), else ``ST_`` and the path
without indices (``ST_gpCh_bahn_state``); arrays ``ARRAY [0..31] OF <element type>``.
"""

from __future__ import annotations

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
        """The struct or array named ``name`` (case-insensitive, ``^`` ignored)."""
        return self._by_name.get(name_key(name))

    def by_handle(self, handle: int) -> Node | None:
        """The struct or array of ``handle``."""
        k = handle - HANDLE_BASE
        return self.symbols[k] if 0 <= k < len(self.symbols) else None

    # ------------------------------------------------------------------ values

    @staticmethod
    def read(node: Node, length: int) -> tuple[int, bytes | str]:
        """The bytes of ``node`` into a buffer of ``length``: its members at their
        offsets, zeros between them; (code, message) when the buffer is too small or a
        member cannot be read."""
        if length < node.size:
            return (_E.DEVICE_INVALIDSIZE,
                    f"{node.name} is {node.type_name}, {node.size} bytes; read length is {length}")
        image = bytearray(node.size)
        for entry, offset in node.leaves:
            code, data = AddressSpace.read_entry(entry, entry.obj.dtype.size)
            if code:
                return code, data
            image[offset : offset + len(data)] = data  # type: ignore[arg-type]
        return 0, bytes(image)

    def decode_write(self, node: Node, data: bytes) -> tuple[int, str, list[tuple[Entry, Any]]]:
        """The member writes that a write of ``data`` to ``node`` makes: each writable
        member whose bytes differ from its value now; (code, message, []) for a write of
        the wrong size, to a struct without writable members, or of a value a member
        refuses (nothing is written then)."""
        if not node.writable:
            return _E.DEVICE_INVALIDACCESS, f"{node.name} has no writable member", []
        if len(data) != node.size:
            return (_E.DEVICE_INVALIDSIZE,
                    f"{node.name} is {node.type_name}, {node.size} bytes; write sent {len(data)}",
                    [])
        code, now = self.read(node, node.size)
        if code:
            return code, str(now), []
        writes: list[tuple[Entry, Any]] = []
        for entry, offset in node.leaves:
            if entry.write is None:
                continue
            part = data[offset : offset + entry.obj.dtype.size]
            if part == now[offset : offset + len(part)]:  # type: ignore[index]
                continue
            code, target, value = AddressSpace.decode_entry_write(entry, part)
            if code:
                return code, str(target), []
            writes.append((entry, value))
        return 0, "", writes


def _leaves(node: Node) -> Iterator[tuple[Entry, int]]:
    """(entry, absolute offset) of every leaf below ``node``."""
    if node.entry is not None:
        yield node.entry, node.start
        return
    for _, child in node.children():
        yield from _leaves(child)
