"""Commands of the tool list, the zero offset table and tool life: writes of the HMI
and the PLC, applied by the cycle thread to the channel's live tables (``tooling``)."""

from __future__ import annotations

import math
from dataclasses import dataclass

from cnc_objects.protocol.constants import TOOL_LIFE_MAX_S

from .kernel_state import KernelState
from .nc.tool_data import TABLE_VALUE_MAX_01UM, ToolField, ToolingTables
from .refusal import Refusal, RefusalReason
from .tooling import show_tables


def _value_refused(what: str, value_01um: float, low_01um: float) -> Refusal | None:
    if not (math.isfinite(value_01um) and low_01um <= value_01um <= TABLE_VALUE_MAX_01UM):
        return Refusal(RefusalReason.INVALID_VALUE,
                       f"{what} = {value_01um:.0f} (0.1 um) is outside "
                       f"{low_01um:.0f}..{TABLE_VALUE_MAX_01UM:.0f} (0.1 um)")
    return None


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
                if not 0.0 <= value <= TOOL_LIFE_MAX_S:  # NaN fails too
                    return Refusal(RefusalReason.INVALID_VALUE,
                                   f"{name}.life_max: {value:g} s is outside 0..{TOOL_LIFE_MAX_S:g}")
            case _:
                value = float(self.value)
                low = 0.0 if self.which == ToolField.RADIUS else -TABLE_VALUE_MAX_01UM
                field = {ToolField.RADIUS: "radius", ToolField.WEAR: "wear"}.get(
                    self.which, "laenge")
                refused = _value_refused(f"{name}.{field}", value, low)
                if refused is not None:
                    return refused
        tables.tools = tables.tools.with_field(self.index, self.which, value)
        show_tables(runner.channel, tables)
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
        if tables.zero_offsets_kept is not None:  # a program wrote offsets: keep this one
            tables.zero_offsets_kept = tables.zero_offsets_kept.with_offset(
                self.group, self.axis_index, len(channel.axes), value)
        show_tables(channel, tables)
        return None


@dataclass(frozen=True, slots=True)
class SetToolLifeUsed:
    """Write ``wz[index].life_used`` (s): typically 0 after a regrind or a new tool."""

    channel_index: int
    index: int
    value_s: float
    cycle_s: float

    def apply(self, state: KernelState) -> Refusal | None:
        ch = state.channels[self.channel_index]
        size = ch.tooling.tools.size
        if not 1 <= self.index <= size:
            return Refusal(RefusalReason.INVALID_VALUE,
                           f"wz[{self.index}]: the tool list has the entries 1..{size}")
        if not 0.0 <= self.value_s <= 1e9:  # NaN fails too
            return Refusal(RefusalReason.INVALID_VALUE,
                           f"wz[{self.index}].life_used: {self.value_s:g} s is outside 0..1e9")
        used = dict(ch.tool_cut_cycles)
        used[self.index] = round(self.value_s / self.cycle_s)
        ch.tool_cut_cycles = used
        return None
