"""Tools and zero offsets of the client, in mm (mixed into ``AsyncClient``).

    tool = await c.active_tool()                          # T, D, radius and length of D
    rows = await c.tools()                                # the tool list wz[1..n]
    await c.set_tool(3, radius_mm=4.0, length_mm=50.0)    # a row, made valid
    table = await c.zero_offsets()                        # G54.. and the positions
    await c.set_zero_offset("G54", {"X": 10.0, "Y": -5.5})

The objects carry 0.1 um; the scale the service gives for each object converts them
(clients/units.py), so nothing here knows a factor. A group is ``G54``..``G59`` or the
index of ``np_grp`` (1..n-1; 7.. are the groups of ``G159 = i``). A value the service
refuses (a negative radius, an offset beyond the position range) raises ``AdsError``
with its sentence. ``cnc tool`` and ``cnc offsets`` are these methods
(docs/tools-offsets.md).
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass

from . import names
from .errors import ClientValueError
from .manual_ops import ManualOps
from .units import engineering

_GROUP = re.compile(r"^(?:G(5[4-9])|(\d+))$", re.IGNORECASE)


@dataclass(frozen=True, slots=True)
class ActiveTool:
    """The tool state of a channel as its objects show it."""

    selected: int  # T selected
    active: int  # T in the spindle
    d: int  # active D (row of the tool list)
    radius_mm: float  # radius of D
    length_mm: float  # length of D


@dataclass(frozen=True, slots=True)
class ToolRow:
    """A row ``wz[i]`` of a channel's tool list."""

    wz: int  # from 1: the T and D number
    valid: bool  # empty rows are refused by T and D
    radius_mm: float
    length_mm: float


@dataclass(frozen=True, slots=True)
class ZeroOffsets:
    """A channel's zero offset table (``np_grp[1..n-1]``), the active group, and the axes'
    positions in machine (ACS) and programmed (PCS) coordinates, all in mm."""

    active_group: int  # np_grp index
    axes: tuple[str, ...]  # by index from 1
    groups: dict[int, dict[str, float]]  # np_grp index -> axis name -> offset (mm)
    positions_mm: dict[str, dict[str, float]]  # axis -> {"acs": mm, "pcs": mm}


def group_name(group: int) -> str:
    """G53..G59 for groups 0..6, ``G159=i`` beyond."""
    return f"G{53 + group}" if group <= 6 else f"G159={group}"


def parse_group(group: str | int) -> int:
    """``G54`` -> 1 ... ``G59`` -> 6; a number is the ``np_grp`` index."""
    if isinstance(group, int):
        return group
    m = _GROUP.match(group.strip())
    if m is None:
        raise ClientValueError(f"zero offset group {group!r}: write G54..G59 or the index 1..n")
    return int(m.group(1)) - 53 if m.group(1) else int(m.group(2))


class ToolingOps(ManualOps):
    """Tools and zero offsets (see the module docstring); the axes by ``ManualOps``."""

    async def _mm(self, names: list[str]) -> dict[str, float]:
        """The values of ``names`` in mm (read in one round trip)."""
        values = await self.read_many(names)
        return {n: engineering(await self.describe(n), values[n]) for n in names}

    async def active_tool(self, channel: int = 1) -> ActiveTool:
        """T selected, T in the spindle, D, and radius and length of D (mm)."""
        p = f"ch{channel}."
        v = await self.read_many(p + n for n in ("mc_selected_tool_r", "mc_active_tool_r",
                                                  "mc_active_tool_offset_r"))
        mm = await self._mm([p + "mc_active_tool_radius_r", p + "mc_active_tool_length_r"])
        return ActiveTool(v[p + "mc_selected_tool_r"], v[p + "mc_active_tool_r"],
                          v[p + "mc_active_tool_offset_r"], mm[p + "mc_active_tool_radius_r"],
                          mm[p + "mc_active_tool_length_r"])

    async def tools(self, channel: int = 1) -> list[ToolRow]:
        """Every row of the channel's tool list, empty ones included."""
        size = await self.read(names.ch(channel).mc_tool_list_size_r)
        rows = [f"ch{channel}.wz[{i}]." for i in range(1, size + 1)]
        valid = await self.read_many(r + "valid" for r in rows)
        mm = await self._mm([r + f for r in rows for f in ("radius", "laenge")])
        return [ToolRow(i, bool(valid[r + "valid"]), mm[r + "radius"], mm[r + "laenge"])
                for i, r in enumerate(rows, start=1)]

    async def set_tool(self, d: int, radius_mm: float | None = None,
                       length_mm: float | None = None, valid: bool = True,
                       channel: int = 1) -> None:
        """Write row ``d`` of the tool list: radius and length (mm, those given), and the
        row valid (``valid=False`` empties it)."""
        row = f"ch{channel}.wz[{d}]."
        if radius_mm is not None:
            await self.write(row + "radius", radius_mm, units=True)
        if length_mm is not None:
            await self.write(row + "laenge", length_mm, units=True)
        await self.write(row + "valid", valid)

    async def zero_offsets(self, channel: int = 1) -> ZeroOffsets:
        """The zero offset table, the active group and the positions (mm)."""
        groups = await self.read(names.ch(channel).mc_zero_offset_groups_r)
        active = await self.read(names.ch(channel).mc_active_zero_offset_r)
        axes = await self.axis_names(channel)
        n = range(1, len(axes) + 1)
        offsets = [f"ch{channel}.ax{a}.np_grp[{g}].v" for g in range(1, groups) for a in n]
        positions = [f"ch{channel}.ax{a}.command_position_{cs}" for a in n for cs in ("acs", "pcs")]
        mm = await self._mm(offsets + positions)
        return ZeroOffsets(
            active, tuple(axes),
            {g: {name: mm[f"ch{channel}.ax{a}.np_grp[{g}].v"] for a, name in zip(n, axes)}
             for g in range(1, groups)},
            {name: {cs: mm[f"ch{channel}.ax{a}.command_position_{cs}"] for cs in ("acs", "pcs")}
             for a, name in zip(n, axes)})

    async def set_zero_offset(self, group: str | int, offsets_mm: Mapping[str, float],
                              channel: int = 1) -> None:
        """Write the offsets (mm, by axis name) of one group (``"G54"`` or the
        ``np_grp`` index)."""
        index = parse_group(group)
        axes = [a.upper() for a in await self.axis_names(channel)]
        for letter, value_mm in offsets_mm.items():
            if letter.upper() not in axes:
                raise ClientValueError(f"{letter}: channel {channel} has the axes "
                                       f"{', '.join(axes)}")
            a = axes.index(letter.upper()) + 1
            await self.write(f"ch{channel}.ax{a}.np_grp[{index}].v", value_mm, units=True)

