"""Tools and work offsets of a channel: the live tables, what the objects show, writes.

The channel runner keeps one ``ToolingTables`` holder (``nc.tool_data``) that its
decoders read through their modal state; the objects' writes replace a table in it on
the cycle thread. ``ChannelTooling`` is the immutable view the channel shows (and the
snapshot keeps): the tables, the tool selected (T), the tool in the spindle (after
M6), D, the zero offset group, and the program shift (zero offset + tool length) the
workpiece positions are computed with. It shows the decoder's state: blocks are decoded
ahead of the path by the look-ahead, so during a run it leads the interpolator.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from cnc_objects.protocol.constants import TOOL_LIFE_MAX_S

from ..machine_config import MachineConfig
from .commands import Refusal, RefusalReason
from .kernel_state import KernelState
from .nc.modal import ModalState
from .nc.tool_data import (
    ToolData,
    ToolField,
    ToolingTables,
    ToolTable,
    ZeroOffsetTable,
    program_shift_mm,
)
from .state import Channel
from .tooling_view import ChannelTooling

# |tool length|, radius and zero offsets the tables take (0.1 um): the largest position
# the SGN32 position objects carry, 214748.3647 mm
TABLE_VALUE_MAX_01UM = float(2**31 - 1)


def tool_list_size(machine: MachineConfig) -> int:
    """Rows of each channel's tool list: ``tool_entries``, or the largest configured D."""
    return max([machine.tool_entries, *(t.d for t in machine.tools)])


def tables_from_config(machine: MachineConfig) -> ToolingTables:
    """A channel's tables at start-up: the configured tool list (``tools``) in a list of
    ``tool_entries`` rows (or more when a configured D is larger), an empty zero offset
    table of ``zero_offset_groups`` groups, and the tool change time."""
    rows = {t.d: ToolData.of_mm(t.radius_mm, t.length_mm) for t in machine.tools}
    size = tool_list_size(machine)
    return ToolingTables(
        tools=ToolTable(rows, size),
        zero_offsets=ZeroOffsetTable(machine.zero_offset_groups),
        tool_change_time_s=machine.tool_change_time_s,
    )



def tooling_of(modal: ModalState, shown: ChannelTooling, axes: tuple[str, ...]
               ) -> ChannelTooling:
    """The view of the state the decoder reached (``shown`` when nothing changed)."""
    tables = modal.tooling
    shift = program_shift_mm(tables, modal.zero_offset_group, modal.tool_offset,
                             int(modal.plane), axes) or (0.0,) * len(axes)
    new = ChannelTooling(
        tables.tools, tables.zero_offsets, modal.tool or 0, modal.spindle_tool,
        modal.tool_offset, modal.zero_offset_group, shift,
    )
    return shown if new == shown else new


def seed_modal(modal: ModalState, tables: ToolingTables, shown: ChannelTooling) -> None:
    """A new run's modal state: the channel's live tables; the tool in the spindle
    carries over (T, D and the zero offset start as none, D0, G53: an M6 needs a T of
    its own run)."""
    modal.tooling = tables
    modal.spindle_tool = shown.tool_active



# ------------------------------------------------------------ writes by objects


def _value_refused(what: str, value_01um: float, low_01um: float) -> Refusal | None:
    if not (math.isfinite(value_01um) and low_01um <= value_01um <= TABLE_VALUE_MAX_01UM):
        return Refusal(RefusalReason.INVALID_VALUE,
                       f"{what} = {value_01um:.0f} (0.1 um) is outside "
                       f"{low_01um:.0f}..{TABLE_VALUE_MAX_01UM:.0f} (0.1 um)")
    return None


LIFE_MAX_S = TOOL_LIFE_MAX_S  # the longest tool life accepted (s)


@dataclass(frozen=True, slots=True)
class SetToolData:
    """Write one field of ``wz[index]`` of a channel's tool list (radius and laenge in
    0.1 um, valid as a flag); in effect from the next block decoded with that D."""

    channel_index: int
    index: int
    which: ToolField
    value: float | bool | str

    def apply(self, state: KernelState) -> Refusal | None:
        runner = state.runners[self.channel_index]
        tables: ToolingTables = runner.tables
        name = f"wz[{self.index}]"
        if not 1 <= self.index <= tables.tools.size:
            return Refusal(RefusalReason.INVALID_VALUE,
                           f"{name}: the tool list has the entries 1..{tables.tools.size}")
        value: float | bool | str = self.value
        match self.which:
            case ToolField.VALID | ToolField.NAME:
                pass
            case ToolField.LIFE_MAX:
                value = float(self.value)
                if not 0.0 <= value <= LIFE_MAX_S:  # NaN fails too
                    return Refusal(RefusalReason.INVALID_VALUE,
                                   f"{name}.life_max: {value:g} s is outside 0..{LIFE_MAX_S:g}")
            case _:
                value = float(self.value)
                low = 0.0 if self.which == ToolField.RADIUS else -TABLE_VALUE_MAX_01UM
                field = {ToolField.RADIUS: "radius", ToolField.WEAR: "wear"}.get(
                    self.which, "laenge")
                refused = _value_refused(f"{name}.{field}", value, low)
                if refused is not None:
                    return refused
        tables.tools = tables.tools.with_field(self.index, self.which, value)
        _show_tables(runner.channel, tables)
        return None


@dataclass(frozen=True, slots=True)
class SetZeroOffset:
    """Write the offset of one channel axis in zero offset group ``group``
    (``np_grp[group]``, 0.1 um); in effect from the next absolute position decoded."""

    channel_index: int
    group: int
    axis_index: int
    value_01um: float

    def apply(self, state: KernelState) -> Refusal | None:
        runner = state.runners[self.channel_index]
        tables: ToolingTables = runner.tables
        groups = tables.zero_offsets.groups
        if not 1 <= self.group < groups:
            return Refusal(RefusalReason.INVALID_VALUE,
                           f"zero offset group {self.group} is outside 1..{groups - 1} "
                           "(group 0 is G53: no offset)")
        channel = runner.channel
        axis = channel.axes[self.axis_index].name
        value = float(self.value_01um)
        refused = _value_refused(f"np_grp[{self.group}] {axis}", value, -TABLE_VALUE_MAX_01UM)
        if refused is not None:
            return refused
        tables.zero_offsets = tables.zero_offsets.with_offset(
            self.group, self.axis_index, len(channel.axes), value)
        _show_tables(channel, tables)
        return None


def _show_tables(channel: Channel, tables: ToolingTables) -> None:
    channel.tooling = replace(channel.tooling, tools=tables.tools,
                              zero_offsets=tables.zero_offsets)
