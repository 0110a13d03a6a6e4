"""Kernel state: channels, logical axes, physical axes, cycle statistics.

The cycle thread owns these mutable objects. At the end of every cycle it publishes a
``Snapshot`` of frozen copies, from which the service answers reads: a read is
consistent within one cycle and never waits for the kernel.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass, field, fields
from enum import IntFlag
from operator import attrgetter
from typing import Any, NamedTuple, Protocol

from cnc_objects.protocol.units import UM01_PER_MM
from cnc_objects.protocol.values import ChannelMode, ChannelState, RapidOverrideMode

# Defined with the wire's value sets; the kernel's modules import them from here.
from cnc_objects.protocol.values import ExecutionMode as ExecutionMode
from cnc_objects.protocol.values import LinkState as LinkState

from ..machine_config import ChannelConfig, MachineConfig
from .alarms import AlarmLog
from .axis_params import AxisParameters
from .nc.technology import MachiningSettings
from .nc.tool_data import ToolingTables
from .plc_functions import PlcFunctions, PlcFunctionsUnit
from .refusal import Refusal
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


BLOCK_START_COLUMN = 1  # the column of an error about a whole block: the block's start


@dataclass(frozen=True, slots=True)
class ErrorEntry:
    """An error of a channel: ISG-style id, text, and where in which NC file it arose.

    Lines and columns count from 1; 0 means none. An error about a whole block (not a word
    of it) is at the block's first column, ``BLOCK_START_COLUMN``."""

    id: int
    text: str
    file: str = ""
    line: int = 0
    column: int = 0
    warning: bool = False  # a warning is listed but does not stop the channel

    def __str__(self) -> str:
        where = f"{self.file}:{self.line}:{self.column}: " if self.file else ""
        kind = "warning" if self.warning else "error"
        return f"{kind} {self.id}: {where}{self.text}"


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
    """A channel: its axes, override, execution mode and path distance."""

    channel_id: int
    name: str
    axes: list[LogicalAxis]
    feed_override_max: int
    feed_override_command: int = 1000  # 0.1 %
    feed_override_per_mille: int = 1000  # 0.1 %
    execution_mode_command: int = 0
    execution_mode_active: int = 0
    dist_prog_start_01um: float = 0.0  # 0.1 um
    output_suspended: bool = False  # suspend_axis_output.state_r: the axes are given up
    mode: ChannelMode = ChannelMode.STANDBY
    state: ChannelState = ChannelState.DESELECTED
    program_name: str = ""  # selected program
    single_block: bool = False
    waiting_for_start: bool = False  # standing at M0/M1 or a single-block stop
    block_number: int = -1  # N of the block in the interpolator; -1 = none
    line: int = 0  # its line in file_name (1-based; 0 = none)
    file_name: str = ""  # file of the block in the interpolator
    file_offset: int = 0  # byte offset of its line in that file
    block_count: int = 0  # blocks finished since program start
    manual_blocks_done: int = 0  # manual blocks finished since the channel started
    path_velocity_mm_s: float = 0.0
    programmed_velocity_mm_s: float = 0.0
    remaining_in_block_mm: float = 0.0
    program_time_s: float = 0.0
    errors: tuple[ErrorEntry, ...] = ()
    error_count: int = 0
    # gpCh[i].bahn_mc_control.suspend_axis_output (ISG control unit, see docs/jog-of-path.md)
    suspend_command_w: bool = False
    suspend_enable_w: bool = True
    suspend_request_r: bool = False
    contour: ContourLookaheadUnit = field(default_factory=ContourLookaheadUnit)
    # gpCh[i].decoder_mc_control.execution_mode (ISG control unit): request_r is the HMI's
    # execution_mode_command; the PLC's command_w counts while enable_w is TRUE
    execution_mode_plc_command: int = 0
    execution_mode_plc_enable: bool = False
    syn_chk: Any = None  # SyntaxCheckConfig for the next check (ch<c>.syn_chk.*)
    decoder_flags: int = 0  # DecoderFlag bits (pMC[i].StateDecoder_Data)
    # #MSG texts of the program, newest first (at most MESSAGES_LISTED), and their count
    messages: tuple[str, ...] = ()
    message_count: int = 0
    # #TRAFO/#HSC/#SLOPE/#FILTER/G133/G134 as decoded so far (nc.technology)
    machining: MachiningSettings = field(default_factory=MachiningSettings)
    prod_time_trace: bool = False  # PROD_TIME runs write their path (ch<c>.prod_time_trace)
    # M/S/T functions output to the PLC and the spindle (kernel.plc_functions, .spindle)
    plc_functions: PlcFunctionsUnit = field(default_factory=PlcFunctionsUnit)
    spindle: SpindleState = field(default_factory=SpindleState)
    manual: tuple[Any, ...] = ()  # ManualAxisView per axis (manual_mode.ManualMode sets)
    tooling: ChannelTooling = field(default_factory=ChannelTooling)  # T, D, zero offsets
    wait_reason: int = 0  # WaitReason: why the channel stands (kernel.wait_reason)
    # operator switches and the rapid override (docs/kernel.md "Operator switches")
    rapid_override_command: int = 1000  # 0.1 %, mc_command_rapid_override_w
    rapid_override_per_mille: int = 1000  # 0.1 %, in effect on G0 (P-CHAN-00181 mode)
    block_ignore_command: int = 0  # skip levels /1../10 (bit n-1), mc_command_block_ignore_w
    block_ignore_active: int = 0  # the mask the running program was started with
    m01_stop_enable: bool = False  # M1 stops only while TRUE (mc_command_M01_stop_enable_w)
    g00_override_mode: int = 2  # RapidOverrideMode (P-CHAN-00181), from the configuration
    # cycles each tool (by T number) has cut: kernel.tool_life; replaced, never changed
    tool_cut_cycles: dict[int, int] = field(default_factory=dict)
    # gpCh[i].decoder_mc_control.program_block_ignore (ISG control unit): the PLC's
    # command_w counts at program start while enable_w is TRUE
    block_ignore_plc_command: int = 0
    block_ignore_plc_enable: bool = False

    @property
    def execution_mode_commanded(self) -> int:
        """The execution mode the next program start takes: the PLC's ``command_w``
        while it enables the unit, else the HMI's request."""
        if self.execution_mode_plc_enable:
            return self.execution_mode_plc_command
        return self.execution_mode_command

    @property
    def block_ignore_commanded(self) -> int:
        """The skip levels the next program start takes: the PLC's ``command_w`` while
        it enables the control unit, else the HMI's ``mc_command_block_ignore_w``."""
        if self.block_ignore_plc_enable:
            return self.block_ignore_plc_command
        return self.block_ignore_command

    @property
    def suspend_commanded(self) -> bool:
        """The value the unit commands: ``command_w`` while the PLC enables the unit,
        else the CNC's own request."""
        return self.suspend_command_w if self.suspend_enable_w else self.suspend_request_r

    def frozen(self) -> Channel:
        """A copy for the snapshot, with copies of its axes.

        The values are read in the order of ``dataclasses.fields`` (``_CHANNEL_VALUES``),
        not a hand-written list: a field added anywhere lands in its own place. Positional
        on purpose: 53 keywords cost two to three times as much per published cycle."""
        copy = Channel(*_CHANNEL_VALUES(self))
        copy.axes = [a.frozen() for a in self.axes]
        return copy


# every field of a Channel in declaration order, read in one C call (Channel.frozen)
_CHANNEL_VALUES = attrgetter(*(f.name for f in fields(Channel)))


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


class ChannelRunnerView(Protocol):
    """What the kernel, its commands and the switchover use of a channel's runner
    (``channel_run.ChannelRunner``, which imports this module)."""

    config: ChannelConfig  # the channel's configuration
    touched: bool  # the last cycle changed the channel's state
    # set when a RESET of the channel is queued: a cycle waiting for its decoder stops
    reset_pending: threading.Event
    plc: PlcFunctions  # the channel's M/S/T functions to the PLC and its spindle
    channel: Channel  # the channel's state, as objects show it
    tables: ToolingTables  # the channel's tool list and zero offset table (live)
    # manual mode of the channel's axes: a manual_mode.ManualMode (that module imports
    # this one, so it is named where it is used: manual_commands)
    manual: Any

    @property
    def moving(self) -> bool:
        """The path is not at standstill."""

    def select_mode(self, mode: int) -> Refusal | None:
        """Choose the operation mode."""

    def select_program(self, name: str) -> Refusal | None:
        """Select a program of the store."""

    def start(self) -> Refusal | None:
        """START."""

    def hold(self) -> Refusal | None:
        """Feedhold."""

    def reset(self) -> Refusal | None:
        """RESET."""

    def manual_block(self, text: str) -> Refusal | None:
        """Run ``text`` as manual blocks (MDI)."""

    def answer_contour_request(self) -> None:
        """Fill the contour look-ahead's response (the PLC set the semaphore)."""

    def internal_hold(self) -> bool:
        """Brake the path for a suspend request; True when this started it."""

    def release_internal_hold(self) -> bool:
        """End the internal feedhold; True when one was active."""

    def initialise_channel(self) -> None:
        """Channel init (start-up, RESET)."""

    def report(self, error: ErrorEntry) -> None:
        """List ``error``."""

    def cycle(self, time_s: float) -> bool:
        """One GEO cycle; True while the channel has motion or decoding to do."""

    def cruise_budget(self, most: int) -> int | None:
        """Cycles (at most ``most``) that may run in bulk; None: its cycles change nothing."""

    def cruise(self, cycles: int, time_s: float) -> None:
        """Run ``cycles`` cycles that ``cruise_budget`` allowed, the last at ``time_s``."""


@dataclass(slots=True)
class KernelState:
    """The live state the cycle thread works on."""

    channels: list[Channel] = field(default_factory=list)
    physical_axes: list[PhysicalAxis] = field(default_factory=list)
    runners: list[ChannelRunnerView] = field(default_factory=list)  # per channel (kernel sets)
    # by logical axis number
    axis_params: dict[int, AxisParameters] = field(default_factory=dict)
    alarms: AlarmLog = field(default_factory=AlarmLog)  # the kernel's (kernel sets)

    @classmethod
    def from_config(cls, config: MachineConfig) -> KernelState:
        """Initial state: every channel links its axes unless its output is suspended."""
        state = cls(
            channels=[_channel_from_config(c, config) for c in config.channels],
            physical_axes=[PhysicalAxis(a.number, a.name) for a in config.physical_axes],
        )
        by_number = state.drive_by_number()
        for channel in state.channels:
            if channel.output_suspended:
                continue
            for axis in channel.axes:
                drive = by_number[axis.requested_link]
                if drive.linked_logical_axis == 0:
                    drive.linked_logical_axis = drive.last_logical_axis = axis.logical_number
                    axis.actual_link = drive.number
                    axis.link_state = LinkState.LINKED
                else:  # another channel holds it: the request waits for it
                    axis.link_state = LinkState.WAITING_ACK
        return state

    def drive_by_number(self) -> dict[int, PhysicalAxis]:
        """The physical axes by number."""
        return {p.number: p for p in self.physical_axes}

    def drive_axes(self) -> None:
        """Position controller: each physical axis follows the increments of the logical
        axis linked to it (ideal drive: actual position = command position). A logical
        axis without a link keeps its output where it was: no step is lost or invented
        when it links again."""
        drives = self.physical_axes
        for channel in self.channels:
            for axis in channel.axes:
                delta = axis.command_position_01um - axis.output_01um
                if not delta or not axis.actual_link:
                    continue
                for drive in drives:
                    if drive.number == axis.actual_link:
                        drive.command_position_01um += delta
                        drive.actual_position_01um = drive.command_position_01um
                        break
                axis.output_01um = axis.command_position_01um

    def snapshot(
        self,
        cycle: int,
        time_ns: int,
        wall_ns: int,
        stats: CycleStats,
        previous: Snapshot | None = None,
        changed: list[bool] | None = None,
        drives_changed: bool = True,
    ) -> Snapshot:
        """Frozen copies of everything readable.

        With ``previous`` and ``changed`` (one flag per channel), a channel that did not
        change this cycle keeps its frozen copy from ``previous``: an idle channel costs
        nothing per cycle. Without them every channel is copied; the physical axes are
        copied unless ``drives_changed`` is False (with ``previous``). ``time_ns`` and
        ``wall_ns``: kernel time and wall-clock time of the cycle (see ``Snapshot``).
        """
        if previous is None or changed is None:
            channels = tuple(c.frozen() for c in self.channels)
        elif not any(changed):
            channels = previous.channels
        else:
            channels = tuple(
                c.frozen() if touched else old
                for c, touched, old in zip(self.channels, changed, previous.channels, strict=True)
            )
        drives = (previous.physical_axes if previous is not None and not drives_changed
                  else tuple(p.frozen() for p in self.physical_axes))
        return Snapshot(cycle, time_ns, wall_ns, stats.frozen(), channels, drives)


def _channel_from_config(config: ChannelConfig, machine: MachineConfig) -> Channel:
    suspended = config.suspend_output_at_start
    axes = [
        LogicalAxis(
            a.name,
            a.logical_number,
            machine.link_of(a.logical_number),
            link_state=LinkState.REQUESTED if suspended else LinkState.LINKED,
        )
        for a in config.axes
    ]
    return Channel(
        config.id,
        config.name,
        axes,
        config.feed_override_max,
        feed_override_command=min(1000, config.feed_override_max),
        feed_override_per_mille=min(1000, config.feed_override_max),
        output_suspended=suspended,
        suspend_command_w=suspended,
        suspend_request_r=suspended,
        syn_chk=config.syn_chk,
        g00_override_mode=RapidOverrideMode[config.g00_override_mode],
    )
