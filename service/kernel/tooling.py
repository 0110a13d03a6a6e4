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

from dataclasses import replace

from ..machine_config import MachineConfig
from .nc.modal import ModalState
from .nc.tool_data import (
    ToolData,
    ToolingTables,
    ToolTable,
    ZeroOffsetTable,
    ZeroOffsetWrite,
    program_shift_mm,
)
from .nc.zero_offset_writes import with_writes
from .state import Channel
from .tooling_view import ChannelTooling


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
        modal.tool_offset, modal.zero_offset_group, shift, tables.nc_zero_offsets,
    )
    return shown if new == shown else new


def seed_modal(modal: ModalState, tables: ToolingTables, shown: ChannelTooling) -> None:
    """A new run's modal state: the channel's live tables; the tool in the spindle
    carries over (T, D and the zero offset start as none, D0, G53: an M6 needs a T of
    its own run)."""
    modal.tooling = tables
    modal.spindle_tool = shown.tool_active


# ------------------------------------------------------------ writes by objects




def show_tables(channel: Channel, tables: ToolingTables) -> None:
    channel.tooling = replace(channel.tooling, tools=tables.tools,
                              zero_offsets=tables.zero_offsets,
                              zero_offsets_kept=tables.zero_offsets_kept)


def show_block_tooling(channel: Channel, view: ChannelTooling) -> None:
    """Show the T, D, zero offset and PCS shift of the block being interpolated
    (``view``, made by the decoder feed), with the live tables (issue 39)."""
    shown = channel.tooling
    channel.tooling = replace(view, tools=shown.tools, zero_offsets=shown.zero_offsets,
                              nc_zero_offsets=(), zero_offsets_kept=shown.zero_offsets_kept)


def apply_nc_zero_offsets(channel: Channel, tables: ToolingTables,
                          writes: tuple[ZeroOffsetWrite, ...]) -> None:
    """The program's ``V.G.NP`` writes into the live table and shown, on the cycle
    thread when the block after them is interpolated (``nc.zero_offset_writes``); the
    table as the operator wrote it stays what the operator data store keeps."""
    table = with_writes(tables.zero_offsets, writes, len(channel.axes))
    if table is not tables.zero_offsets:
        if tables.zero_offsets_kept is None:
            tables.zero_offsets_kept = tables.zero_offsets
        tables.zero_offsets = table
        show_tables(channel, tables)
