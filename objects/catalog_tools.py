"""The catalog of tools and work offsets: active tool, D, zero offset, the tool list
``wz[i]``, the zero offset table ``np_grp[i]``, positions in workpiece coordinates.

ISG documents the data (the tool list ``wz[i].radius`` / ``wz[i].laenge`` of P-TOOL, the
zero offset groups ``np_grp[i]`` of P-ZERO, selected by D, T, G53..G59, G159) but not
COM offsets for reading them; those offsets are this project's ("project" in the
description) and found by name through the COM object directory. Two GEO objects have
the offsets a public client reads (TwinSharp): the active zero offset group (0x12) and
the actual tool radius (0x2C). The table objects exist per channel, as many as the
machine configures (``tool_entries``, ``zero_offset_groups``). docs/tools-offsets.md
lists every object with its source.
"""

from __future__ import annotations

from cnc_objects.protocol.constants import TOOL_NAME_CHARS, CncPort
from cnc_objects.protocol.datatypes import BOOLEAN, REAL64, SGN32, STRING, UNS16, UNS32

from .addressing import GroupBase
from .model import Access
from .templates import CatalogSizes, ObjectTemplate, Scope

R, RW = Access.READ, Access.READ_WRITE
GEO, COM = CncPort.GEO, CncPort.COM
IPO = GroupBase.GEO_INTERPOLATOR
COM_CH = GroupBase.COM_CHANNEL

TOOL_LIST_OFFSET, TOOL_ROW_STRIDE = 0x5000, 4  # ch<c>.wz[i].<field> at 0x5000 + 4 i + k
ZERO_OFFSET_OFFSET = 0x4000  # ch<c>.ax<a>.np_grp[i].v at 0x<a>4000 + i
#: the fields of one tool list row: (name, index in the row, type, unit, meaning)
TOOL_ROW_FIELDS = (
    ("valid", 0, BOOLEAN, "-", "the row holds tool data: T<i> and D<i> may name it"),
    ("radius", 1, REAL64, "0.1 um",
     "tool radius (P-TOOL-00004): G41/G42 compensate by it (>= 0)"),
    ("laenge", 2, REAL64, "0.1 um",
     "tool length (P-TOOL-00003), along the tool axis (G17: Z, G18: Y, G19: X)"),
)

#: name, wear and life of a tool list row (project: ISG's wz[i] has none of them; an
#: external tool management keeps them there): (name, index, type, access, unit, meaning)
#: in the project group COM 0x12060<c>, offset 8 i + index
TOOL_EXTRA_STRIDE = 8
TOOL_EXTRA_FIELDS = (
    ("name", 0, STRING(TOOL_NAME_CHARS), RW, "-", "the tool's name"),
    ("wear", 1, REAL64, RW, "0.1 um",
     "radius wear: G41/G42 compensate by radius + wear (negative: the tool is worn smaller)"),
    ("life_max", 2, REAL64, RW, "s", "cutting time the tool may run; 0 = no limit"),
    ("life_used", 3, REAL64, RW, "s",
     "cutting time run: counts while the tool is in the spindle (the T of the last M6) and "
     "a G1/G2/G3 block is in the interpolator; write 0 after a regrind or a new tool"),
    ("life_expired", 4, BOOLEAN, R, "-", "life_max set and life_used >= life_max"),
)

TOOL_TEMPLATES: tuple[ObjectTemplate, ...] = (
    ObjectTemplate(
        "mc_selected_tool_r", Scope.CHANNEL, COM, COM_CH, 0x3500, UNS32, R, "-",
        "T programmed last: the tool the next M6 changes to; 0 = none (project offset)",
    ),
    ObjectTemplate(
        "mc_active_tool_r", Scope.CHANNEL, COM, COM_CH, 0x3501, UNS32, R, "-",
        "Tool in the spindle: the T of the last M6; 0 = none (project offset)",
    ),
    ObjectTemplate(
        "mc_active_tool_offset_r", Scope.CHANNEL, COM, COM_CH, 0x3502, UNS32, R, "-",
        "D in effect: the tool list row of radius and length; 0 = D0 (project offset)",
    ),
    ObjectTemplate(
        "mc_active_tool_radius_r", Scope.CHANNEL, COM, COM_CH, 0x3503, REAL64, R, "0.1 um",
        "Radius of the active D (V.G.WZ_AKT.R) (project offset)",
    ),
    ObjectTemplate(
        "mc_active_tool_length_r", Scope.CHANNEL, COM, COM_CH, 0x3504, REAL64, R, "0.1 um",
        "Length of the active D along the tool axis (project offset)",
    ),
    ObjectTemplate(
        "mc_active_zero_offset_r", Scope.CHANNEL, COM, COM_CH, 0x3505, UNS16, R, "-",
        "Zero offset group in effect: 0 G53, 1..6 G54..G59, 7.. G159 = i (project offset)",
    ),
    ObjectTemplate(
        "mc_tool_list_size_r", Scope.CHANNEL, COM, COM_CH, 0x3506, UNS32, R, "-",
        "Rows wz[1..n] of the channel's tool list (project offset)",
    ),
    ObjectTemplate(
        "mc_zero_offset_groups_r", Scope.CHANNEL, COM, COM_CH, 0x3507, UNS16, R, "-",
        "Zero offset groups np_grp[0..n-1] (P-ZERO-00003) (project offset)",
    ),
    ObjectTemplate(
        "active_zero_offset_group", Scope.CHANNEL, GEO, IPO, 0x12, UNS16, R, "-",
        "Active zero offset group (0 = G53)",
    ),
    ObjectTemplate(
        "actual_tool_radius", Scope.CHANNEL, GEO, IPO, 0x2C, REAL64, R, "0.1 um",
        "Radius of the active tool (D)",
    ),
    ObjectTemplate(
        "command_position_pcs", Scope.CHANNEL_AXIS, COM, COM_CH, 0x06, SGN32, R, "0.1 um",
        "Command position in workpiece coordinates: ACS - zero offset - tool length",
    ),
    ObjectTemplate(
        "actual_position_pcs", Scope.CHANNEL_AXIS, COM, COM_CH, 0x07, SGN32, R, "0.1 um",
        "Actual position in workpiece coordinates (the ideal drive: = command)",
    ),
)


def tool_row_element(i: int, field: str) -> str:
    """Element name of a tool list field: ``wz[<i>].<field>``."""
    return f"wz[{i}].{field}"


def zero_offset_element(group: int) -> str:
    """Element name of a zero offset: ``np_grp[<i>].v`` (per channel axis)."""
    return f"np_grp[{group}].v"


def table_templates(tool_entries: int, zero_offset_groups: int) -> tuple[ObjectTemplate, ...]:
    """The rows of the tool list (1..tool_entries) and the zero offset groups
    (1..groups-1; group 0 is G53, no offset)."""
    rows = tuple(
        ObjectTemplate(
            tool_row_element(i, name), Scope.CHANNEL, COM, COM_CH,
            TOOL_LIST_OFFSET + TOOL_ROW_STRIDE * i + k, dtype, RW, unit,
            f"Tool list row {i}: {meaning} (project offset)",
        )
        for i in range(1, tool_entries + 1)
        for name, k, dtype, unit, meaning in TOOL_ROW_FIELDS
    )
    extras = tuple(
        ObjectTemplate(
            tool_row_element(i, name), Scope.CHANNEL, COM, GroupBase.COM_TOOL_LIST,
            TOOL_EXTRA_STRIDE * i + k, dtype, access, unit,
            f"Tool list row {i}: {meaning} (project group and offset)",
        )
        for i in range(1, tool_entries + 1)
        for name, k, dtype, access, unit, meaning in TOOL_EXTRA_FIELDS
    )
    groups = tuple(
        ObjectTemplate(
            zero_offset_element(g), Scope.CHANNEL_AXIS, COM, COM_CH, ZERO_OFFSET_OFFSET + g,
            REAL64, RW, "0.1 um",
            f"Zero offset of the axis in group {g} ({_g_function(g)}) (project offset)",
        )
        for g in range(1, zero_offset_groups)
    )
    return rows + extras + groups


def _g_function(group: int) -> str:
    return f"G{53 + group}" if group <= 6 else f"G159 = {group}"


def tool_templates(sizes: CatalogSizes) -> tuple[ObjectTemplate, ...]:
    """The tool and work offset templates: the fixed ones and the tables of ``sizes``."""
    return TOOL_TEMPLATES + table_templates(sizes.tool_entries, sizes.zero_offset_groups)
