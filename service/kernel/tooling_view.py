"""What a channel shows of its tools and work offsets: an immutable view (the snapshot
keeps it without copying). ``tooling`` builds and changes it."""

from __future__ import annotations

from dataclasses import dataclass, field, replace

from .nc.tool_data import ToolingTables, ToolTable, ZeroOffsetTable, ZeroOffsetWrite


@dataclass(frozen=True, slots=True)
class ChannelTooling:
    """What a channel shows of its tools and work offsets (immutable)."""

    tools: ToolTable = field(default_factory=lambda: ToolTable({}, 0, checks_tools=False))
    zero_offsets: ZeroOffsetTable = field(default_factory=ZeroOffsetTable)
    tool_selected: int = 0  # T programmed last (0: none)
    tool_active: int = 0  # T in the spindle: the T of the last M6 (0: none)
    d_active: int = 0  # D in effect (0: no compensation data)
    zero_offset_group: int = 0  # np_grp index in effect (0: G53)
    shift_mm: tuple[float, ...] = ()  # program shift per channel axis (PCS = ACS - shift)
    # in a view the decoder feed made: the zero offsets the program wrote so far, for the
    # kernel to apply when the block is interpolated; () in what the channel shows
    nc_zero_offsets: tuple[ZeroOffsetWrite, ...] = ()
    # the table without the programs' writes, when they changed it (None: zero_offsets)
    zero_offsets_kept: ZeroOffsetTable | None = None

    @property
    def zero_offsets_to_keep(self) -> ZeroOffsetTable:
        """The zero offsets the operator data store keeps: as the operator wrote them."""
        kept = self.zero_offsets_kept
        return self.zero_offsets if kept is None else kept

    @property
    def radius_01um(self) -> float:
        """Radius of the active D as the table holds it (0.1 um; 0 for D0)."""
        row = self.tools.row(self.d_active)
        return row.radius_01um if self.d_active and row.valid else 0.0

    @property
    def length_01um(self) -> float:
        """Length of the active D as the table holds it (0.1 um; 0 for D0)."""
        row = self.tools.row(self.d_active)
        return row.length_01um if self.d_active and row.valid else 0.0


def initial_tooling(tables: ToolingTables, axis_count: int) -> ChannelTooling:
    """What a channel shows at start-up: no tool, D0, G53."""
    return ChannelTooling(tables.tools, tables.zero_offsets, shift_mm=(0.0,) * axis_count)


def after_reset(shown: ChannelTooling) -> ChannelTooling:
    """RESET: D0 and G53 (the initial state); the tool stays in the spindle."""
    return replace(shown, d_active=0, zero_offset_group=0,
                   shift_mm=(0.0,) * len(shown.shift_mm))
