"""Kernel state: channels, logical axes, physical axes, cycle statistics.

The cycle thread owns these mutable objects. At the end of every cycle it publishes a
``Snapshot`` of frozen copies, from which the service answers reads: a read is
consistent within one cycle and never waits for the kernel.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import IntFlag
from typing import NamedTuple

from cnc_objects.protocol.units import UM01_PER_MM
from cnc_objects.protocol.values import ChannelMode, ChannelState

# Defined with the wire's value sets; the kernel's modules import them from here.
from cnc_objects.protocol.values import ExecutionMode as ExecutionMode
from cnc_objects.protocol.values import LinkState as LinkState

from .channel_parts import BLOCK_START_COLUMN as BLOCK_START_COLUMN
from .channel_parts import (
    BlockShown,
    ChannelErrors,
    ChannelSwitches,
    PathShown,
    ProgramShown,
    SuspendUnit,
)
from .channel_parts import ErrorEntry as ErrorEntry
from .manual_view import ManualAxisView
from .plc_functions import PlcFunctionsUnit
from .spindle import SpindleState
from .tooling_view import ChannelTooling


class DecoderFlag(IntFlag):
    """Display flags of the decoder (``pMC[i].StateDecoder_Data``, FCT-C9)."""

    SYNTAX_CHECK = 0x1  # X_SyntaxCheck: the decoder works in the syntax check
    WAIT_AFTER_ERROR = 0x2  # X_WaitAfterError: waits after an error for continue/abort
    SYNTAX_CHECK_RELEASE_CLEARED = 0x4  # X_SyntaxCheckReleaseNextBlockCleared
    WAIT_CONTINUE = 0x8  # X_WaitContinue: decoding interrupted (single step, STOP)
    WAIT_RELEASE_CLEARED = 0x10  # X_WaitReleaseNextBlockCleared


@dataclass(slots=True)
class PhysicalAxis:
    """A drive: follows the increments of the logical axis linked to it."""

    number: int
    name: str
    command_position_01um: int = 0  # 0.1 um
    actual_position_01um: int = 0  # 0.1 um
    linked_logical_axis: int = 0  # logical axis number driving it; 0 = none
    last_logical_axis: int = 0  # the logical axis that was linked last (survives unlinking)
    position_offset_01um: int = 0  # offset of the link: command of the linked axis - position

    def frozen(self) -> PhysicalAxis:
        """A copy for the snapshot."""
        return PhysicalAxis(
            self.number,
            self.name,
            self.command_position_01um,
            self.actual_position_01um,
            self.linked_logical_axis,
            self.last_logical_axis,
            self.position_offset_01um,
        )


@dataclass(slots=True)
class LogicalAxis:
    """An axis of a channel, its command position and its link to a physical axis."""

    name: str
    logical_number: int
    requested_link: int  # physical axis number the axis asks for
    actual_link: int = 0  # physical axis number linked now; 0 = none
    link_state: LinkState = LinkState.LINKED
    position_mm: float = 0.0  # command position of the channel axis
    command_position_01um: int = 0  # the same in 0.1 um, as the objects show it
    output_01um: int = 0  # command position last handed to the physical axis
    position_offset_01um: int = 0  # command position - physical position (jog of path)
    offset_live: bool = False  # the axis took its drive over from another logical axis
    released: bool = False  # left the channel by #AX RELEASE
    distance_to_go_01um: int = 0  # to the end of the block in the interpolator (0.1 um)

    def frozen(self) -> LogicalAxis:
        """A copy for the snapshot."""
        return LogicalAxis(
            self.name, self.logical_number, self.requested_link, self.actual_link,
            self.link_state, self.position_mm, self.command_position_01um, self.output_01um,
            self.position_offset_01um, self.offset_live, self.released,
            self.distance_to_go_01um,
        )

    def set_position_01um(self, incr: int) -> None:
        """Move the command position to ``incr`` without handing a step to the drive
        (a position adjustment: the channel takes the drive's position)."""
        self.command_position_01um = self.output_01um = incr
        self.position_mm = incr / UM01_PER_MM


class ContourElement(NamedTuple):
    """One entry of a contour look-ahead reply (``HLI_CONTOUR_LOOKAHEAD_BLOCK``).

    Distances and radii in 0.1 um on the compensated path, angles in rad.
    """

    block_type: int  # 0 none, 1 linear, 2 circular, 3 LOG ON, 4 LOG PARAM, 5 LOG OFF
    block_number: int  # programmed N; -1 = the block has none
    block_count_r: int  # the block's number in the run: mc_block_count_r once it is done
    start_position: float  # path distance at its start (sum of the earlier lengths)
    length: float  # element length; for types 3..5 the PARAM value as programmed
    programmed_radius: float  # radius of the programmed arc; 0 for lines
    compensated_radius: float  # radius of the arc on the compensated path; 0 for lines
    circle_angle: float  # swept angle: cw in [-2pi, 0), ccw in (0, 2pi]; 0 for lines
    length_min: float  # length on the scaled contour of die sinking: 0 (no die sinking)
    tangent_variation: float  # angle to the previous motion element, in [0, pi]


@dataclass(frozen=True, slots=True)
class ContourLookaheadUnit:
    """``gpCh[i].contour_lookahead``: the PLC's request, the handshake, state, reply.

    Immutable: a change replaces the whole unit (``dataclasses.replace``), which happens
    when blocks are prepared or a request comes, so the snapshot of a running channel
    shares it instead of copying it every cycle."""

    request_start_position: float = 0.0  # mode 1: index; mode 2: distance (0.1 um)
    request_length: float = 0.0  # 0: mode 1 (by index); else mode 2 (by distance)
    semaphor: bool = False  # TRUE: a request waits; the CNC answers and resets it
    max_dist_prog_start_01um: float = 0.0  # end of the path prepared so far (0.1 um)
    count_logged_blocks: int = 0  # entries in the log of the marked area
    log_active: bool = False  # the marked area is open and not all of it was read in
    response: tuple[ContourElement, ...] = ()  # the last reply (at most N entries)


@dataclass(slots=True)
class Channel:
    """A channel: its axes, its mode and state, and its immutable parts
    (``channel_parts``: each replaced whole by the one module that owns it)."""

    channel_id: int
    name: str
    axes: list[LogicalAxis]
    switches: ChannelSwitches
    suspend: SuspendUnit = field(default_factory=SuspendUnit)
    mode: ChannelMode = ChannelMode.STANDBY
    state: ChannelState = ChannelState.DESELECTED
    wait_reason: int = 0  # WaitReason: why the channel stands (kernel.wait_reason)
    program: ProgramShown = field(default_factory=ProgramShown)
    block: BlockShown = BlockShown()
    path: PathShown = PathShown()
    errors: ChannelErrors = field(default_factory=ChannelErrors)
    manual: tuple[ManualAxisView, ...] = ()  # per axis (manual_mode.ManualMode.publish)
    tooling: ChannelTooling = field(default_factory=ChannelTooling)  # T, D, zero offsets
    # cycles each tool (by T number) has cut: kernel.tool_life; replaced, never changed
    tool_cut_cycles: dict[int, int] = field(default_factory=dict)
    contour: ContourLookaheadUnit = field(default_factory=ContourLookaheadUnit)
    # M/S/T functions output to the PLC and the spindle: the state of the channel's
    # plc_functions.PlcFunctions and spindle.Spindle, which keep it here (no copy)
    plc_functions: PlcFunctionsUnit = field(default_factory=PlcFunctionsUnit)
    spindle: SpindleState = field(default_factory=SpindleState)

    def frozen(self) -> Channel:
        """A copy for the snapshot: copies of its axes, its parts shared (they are
        immutable). Built by keyword: a field added anywhere lands in its own place."""
        return Channel(
            channel_id=self.channel_id, name=self.name,
            axes=[a.frozen() for a in self.axes],
            switches=self.switches, suspend=self.suspend, mode=self.mode,
            state=self.state, wait_reason=self.wait_reason, program=self.program,
            block=self.block, path=self.path, errors=self.errors, manual=self.manual,
            tooling=self.tooling, tool_cut_cycles=self.tool_cut_cycles,
            contour=self.contour, plc_functions=self.plc_functions, spindle=self.spindle,
        )


@dataclass(slots=True)
class CycleStats:
    """Statistics of the GEO cycle task."""

    cycle_us: int
    cycles: int = 0
    overruns: int = 0
    jitter_max_us: int = 0
    exec_time_max_us: int = 0
    running: bool = True
    # of ``cycles``: those run in bulk steps (``Kernel._run_in_bulk``: the event-speed
    # virtual clock, the step clock's unwatched granted cycles)
    bulk_cycles: int = 0

    def frozen(self) -> CycleStats:
        """A copy for the snapshot."""
        return CycleStats(
            self.cycle_us,
            self.cycles,
            self.overruns,
            self.jitter_max_us,
            self.exec_time_max_us,
            self.running,
            self.bulk_cycles,
        )


@dataclass(frozen=True, slots=True)
class Snapshot:
    """Everything readable, as it was at the end of one cycle.

    ``time_ns`` is kernel time (cycles x cycle time); ``wall_ns`` the wall-clock time
    (``time.time_ns()``, ns since the Unix epoch) at which the cycle published it. With
    the virtual clock the two drift apart; samples are stamped with ``wall_ns``.
    """

    cycle: int
    time_ns: int
    wall_ns: int
    stats: CycleStats
    channels: tuple[Channel, ...]
    physical_axes: tuple[PhysicalAxis, ...]
