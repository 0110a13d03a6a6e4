"""Tool data and zero offsets as the decoder reads them (ISG ``wz[i]``, ``np_grp[i]``).

The tool list is ISG's ``wz[i]`` structure of the tool data (P-TOOL): with
P-TOOL-00140 = 0 (ISG's default) the index ``i`` is the tool number, so ``T<i>`` and
``D<i>`` both name the row ``wz[i]``: ``T`` selects the tool for the next ``M6``, ``D``
its compensation data (radius for G41/G42, length along the tool axis). A row exists
when it is ``valid``.

The zero offset table is ISG's ``np_grp[i]`` (P-ZERO): group 0 is ``G53`` (no offset,
P-ZERO-00001 = 0), 1..6 are ``G54``..``G59``, further groups are reached by
``G159 = <i>``. Each group holds one offset per channel axis (mm).

Both tables are immutable values: a write makes a new table and the ``ToolingTables``
holder of the channel points at it, so a decoder always reads the newest table and a
snapshot may keep the old one without copying.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field, replace
from enum import IntEnum

from cnc_objects.protocol.units import UM01_PER_MM

# the tool axis of each working plane (G17, G18, G19): the tool length acts along it
TOOL_AXIS_OF_PLANE = {17: "Z", 18: "Y", 19: "X"}


class ToolField(IntEnum):
    """The fields of one ``wz[i]`` row the objects write."""

    VALID = 0  # wz[i].valid: the row holds tool data
    RADIUS = 1  # wz[i].radius: tool radius (G41/G42), P-TOOL-00004
    LENGTH = 2  # wz[i].laenge: tool length along the tool axis, P-TOOL-00003
    NAME = 3  # wz[i].name: the tool's name (project)
    WEAR = 4  # wz[i].wear: radius wear, added to the radius G41/G42 use (project)
    LIFE_MAX = 5  # wz[i].life_max: cutting time the tool may run, s; 0 = no limit (project)




@dataclass(frozen=True, slots=True)
class ToolData:
    """One row ``wz[i]`` of the tool list. The values are kept as written (0.1 um, ISG's
    unit of P-TOOL-00003/4), so a read gives back exactly what was written."""

    valid: bool = False
    radius_01um: float = 0.0
    length_01um: float = 0.0
    name: str = ""  # the operator's name of the tool (project)
    wear_01um: float = 0.0  # radius wear: compensation uses radius + wear (project)
    life_max_s: float = 0.0  # cutting time allowed; 0 = no limit (project)

    @classmethod
    def of_mm(cls, radius_mm: float, length_mm: float = 0.0, valid: bool = True) -> ToolData:
        """A row from millimetres."""
        return cls(valid, radius_mm * UM01_PER_MM, length_mm * UM01_PER_MM)

    @property
    def radius_mm(self) -> float:
        """Tool radius (mm)."""
        return self.radius_01um / UM01_PER_MM

    @property
    def length_mm(self) -> float:
        """Tool length (mm)."""
        return self.length_01um / UM01_PER_MM


class ToolTable(Mapping[int, float]):
    """The tool list ``wz[1..size]``; as a Mapping it gives the radius of each valid
    row by D number (the decoder's radius compensation reads it that way).

    ``checks_tools`` False: a table made from radii alone (unit tests, syntax tools)
    accepts every T number; a channel's table (``checks_tools`` True) accepts T0 and
    the valid rows only.
    """

    __slots__ = ("rows", "size", "checks_tools")

    def __init__(self, rows: Mapping[int, ToolData], size: int, checks_tools: bool = True):
        self.rows = dict(rows)
        self.size = size
        self.checks_tools = checks_tools

    @classmethod
    def from_radii(cls, radii: Mapping[int, float]) -> ToolTable:
        """A table from D number -> radius (every T number accepted)."""
        rows = {d: ToolData.of_mm(float(r)) for d, r in radii.items()}
        return cls(rows, max(rows, default=0), checks_tools=False)

    def __getitem__(self, d: int) -> float:
        row = self.rows.get(d)
        if row is None or not row.valid:
            raise KeyError(d)
        return (row.radius_01um + row.wear_01um) / UM01_PER_MM  # worn tool: radius + wear

    def __iter__(self) -> Iterator[int]:
        return (d for d, row in sorted(self.rows.items()) if row.valid)

    def __len__(self) -> int:
        return sum(1 for row in self.rows.values() if row.valid)

    def row(self, i: int) -> ToolData:
        """Row ``wz[i]`` (an empty row when never written)."""
        return self.rows.get(i, ToolData())

    def length_mm(self, d: int) -> float:
        """Length of row D (0 for D0 or an invalid row)."""
        row = self.rows.get(d)
        return row.length_mm if row is not None and row.valid else 0.0

    def knows_tool(self, t: int) -> bool:
        """True when ``T<t>`` names a tool: T0 (no tool) or a valid row."""
        if t == 0 or not self.checks_tools:
            return True
        return self.row(t).valid

    def with_field(self, i: int, which: ToolField, value: float | bool | str) -> ToolTable:
        # ``value``: the flag, or a length in 0.1 um
        """A new table with one field of row ``i`` changed (each field on its own: a
        radius written to an empty row leaves it empty until ``valid`` is set)."""
        row = self.row(i)
        match which:
            case ToolField.VALID:
                row = replace(row, valid=bool(value))
            case ToolField.RADIUS:
                row = replace(row, radius_01um=float(value))
            case ToolField.LENGTH:
                row = replace(row, length_01um=float(value))
            case ToolField.NAME:
                row = replace(row, name=str(value))
            case ToolField.WEAR:
                row = replace(row, wear_01um=float(value))
            case ToolField.LIFE_MAX:
                row = replace(row, life_max_s=float(value))
        rows = dict(self.rows)
        rows[i] = row
        return ToolTable(rows, self.size, self.checks_tools)


@dataclass(frozen=True, slots=True)
class ZeroOffsetTable:
    """``np_grp[0..groups-1]``: the offset of each channel axis per group, kept as
    written (0.1 um). Group 0 (G53) is always zero."""

    groups: int = 10
    offsets_01um: Mapping[int, tuple[float, ...]] = field(default_factory=dict)

    @classmethod
    def of_mm(cls, groups: int, offsets_mm: Mapping[int, tuple[float, ...]]
              ) -> ZeroOffsetTable:
        """A table from millimetres."""
        return cls(groups, {g: tuple(v * UM01_PER_MM for v in values)
                            for g, values in offsets_mm.items()})

    def offset_01um(self, group: int, axis: int) -> float:
        """Offset of channel axis ``axis`` (index from 0) in ``group``, as written."""
        values = self.offsets_01um.get(group)
        return values[axis] if values is not None and axis < len(values) else 0.0

    def offset_mm(self, group: int, axis: int) -> float:
        """Offset of channel axis ``axis`` (index from 0) in ``group`` (mm)."""
        return self.offset_01um(group, axis) / UM01_PER_MM

    def with_offset(self, group: int, axis: int, axis_count: int, value_01um: float
                    ) -> ZeroOffsetTable:
        """A new table with one axis offset of ``group`` changed."""
        values = list(self.offsets_01um.get(group, ()))
        values += [0.0] * (axis_count - len(values))
        values[axis] = float(value_01um)
        offsets = dict(self.offsets_01um)
        offsets[group] = tuple(values)
        return ZeroOffsetTable(self.groups, offsets)


# |tool length|, radius and zero offsets the tables take (0.1 um): the largest position
# the SGN32 position objects carry, 214748.3647 mm
TABLE_VALUE_MAX_01UM = float(2**31 - 1)

# A zero offset an NC program wrote: (group, channel axis index, value in 0.1 um)
ZeroOffsetWrite = tuple[int, int, float]


@dataclass(slots=True)
class ToolingTables:
    """The channel's live tables: the holder the decoder and the objects share. The
    objects' writes (on the cycle thread) replace a table; the decoder reads the
    newest one at every block.

    A run whose program writes ``V.G.NP[j]`` decodes on a copy of its own from then on
    (``nc_zero_offsets`` the writes, the last per group and axis): the kernel applies them
    to the live holder when the next block is interpolated (``nc.zero_offset_writes``)."""

    tools: ToolTable = field(default_factory=lambda: ToolTable({}, 0, checks_tools=False))
    zero_offsets: ZeroOffsetTable = field(default_factory=ZeroOffsetTable)
    tool_change_time_s: float = 0.0  # M6: the path waits this long (tool change)
    nc_zero_offsets: tuple[ZeroOffsetWrite, ...] = ()  # always () in the live holder
    # live holder: the zero offsets as the operator wrote them, once a program's writes
    # differ (None: the same): what the operator data store keeps, for ISG says an NC
    # write lasts "until the next interpretation of the list (... start-up)"
    zero_offsets_kept: ZeroOffsetTable | None = None


def program_shift_mm(tables: ToolingTables, group: int, d: int, plane: int,
                     axes: tuple[str, ...]) -> tuple[float, ...] | None:
    """What a programmed absolute position adds per channel axis: the zero offset of
    ``group`` plus the tool length of D along the tool axis of ``plane`` (G17: Z,
    G18: Y, G19: X). None when nothing is added (the common case)."""
    zero = tables.zero_offsets
    shift = [zero.offset_mm(group, k) for k in range(len(axes))] if group else [0.0] * len(axes)
    length = tables.tools.length_mm(d) if d else 0.0
    if length:
        tool_axis = TOOL_AXIS_OF_PLANE.get(plane)
        if tool_axis in axes:
            shift[axes.index(tool_axis)] += length
    if not any(shift):
        return None
    return tuple(shift)
