"""One channel at work: its mode and state, and the run it starts, holds and ends.

(Over 600 lines, on purpose: this is the one place where the channel's commands, the
begin and end of its runs and its state transitions meet; what stands alone lives in
channel_transitions, program_run, channel_check, manual_mode, plc_functions and
tooling, and each of those is called from here in a line or two.)

The GEO cycle calls ``ChannelRunner.cycle`` once per cycle; commands (select, start,
feedhold, RESET, manual block) call the other methods, also on the cycle thread, and
answer None or a ``Refusal`` with the reason. Every change of the channel's state goes
through ``_move``, which looks it up in ``channel_transitions.TRANSITIONS``.

The runner owns what lasts for the channel's life (mode, modal state between manual
blocks, messages, the contour look-ahead log a PLC may read after the run); what
belongs to one run lives in the run (``self._run``): a ``ProgramRun``, a
``ProdTimeRun`` (PROD_TIME) or a ``ChannelCheck`` (SYNCHK, MACHINE_LOCK), created when
the run begins and dropped when it ends, fails or is RESET.

Errors take effect where they are in the program: the blocks before an erroneous block
run to their end, the path stops there, and the channel goes to ERROR with the error
(id, text, file, line, column) in its error list. A block that would leave a software
limit is refused before it moves.
"""

from __future__ import annotations

import logging
import threading
from collections import deque
from dataclasses import replace
from functools import partial

from cnc_objects.protocol.units import UM01_PER_MM
from cnc_objects.protocol.values import ERRORS_LISTED, MESSAGES_LISTED, WORKING_STATES, ExecutionMode

from ..machine_config import ChannelConfig
from .alarms import AlarmClass
from .axis_params import AxisErrorId, monitored_limits_mm
from .channel_check import ChannelCheck
from .channel_mode import SELECTABLE_MODES, ChannelMode, ChannelState, describe
from .channel_parts import ChannelErrors
from .channel_transitions import ChannelEvent, allowed, next_state
from .commands import Refusal, RefusalReason
from .contour_lookahead import ContourLog
from .decoder_feed import DecoderFeed, Job
from .manual_mode import ManualMode
from .nc import ModalState
from .nc.blocks import LogArea, LookAheadMark, ManualModeRequest, TrafoUse
from .nc.technology import HscProgram, MachiningSettings, Surroundings
from .nc.tool_data import ToolingTables, ZeroOffsetWrite
from .path.executor import AxisDynamics, PathExecutor
from .path.section_plan import plan_section
from .path_kinematics import PathKinematics
from .plc_functions import PlcFunctions, show_technology
from .prod_time_trace import ProdTimeTrace
from .program_run import (
    ChannelRun,
    ProdTimeRun,
    ProgramRun,
    Step,
    log_full_warning,
    show_contour_state,
)
from .runner_services import RunnerServices
from .spindle import Spindle
from .state import Channel, DecoderFlag, ErrorEntry
from .syntax_check import SYNCHK_WITHOUT_MACHINE_LOCK, CheckRun
from .tooling import apply_nc_zero_offsets, seed_modal, tables_from_config
from .tooling_view import after_reset, initial_tooling
from .wait_reason import WaitReason, channel_wait_reason

log = logging.getLogger(__name__)

_ACTIVE = int(ChannelState.ACTIVE)
_NOT_WAITING = int(WaitReason.NONE)
_FEED_MARGIN_BLOCKS = 256  # the decoder may run this far ahead of the look-ahead buffer
_MDI_NAME = "MDI"  # file name of manual blocks in errors and objects
_CHECK_MODES = ExecutionMode.SYNCHK | ExecutionMode.MACHINE_LOCK
_PROGRAM_MODES = _CHECK_MODES | ExecutionMode.PROD_TIME | ExecutionMode.SUPPRESS_TECHNO_OUTPUT


def _not_ready(channel: Channel, what: str) -> Refusal:
    return Refusal(
        RefusalReason.NOT_READY,
        f"channel {channel.channel_id} is {describe(channel.mode, channel.state)}: {what}",
    )


class ChannelRunner:
    """The working parts of one channel, driven by the GEO cycle."""

    def __init__(self, channel: Channel, config: ChannelConfig, services: RunnerServices,
                 tables: ToolingTables | None = None) -> None:
        """``channel`` is the state the runner works on, ``config`` its configuration;
        ``services`` what the kernel shares with every channel (``RunnerServices``);
        ``tables``: the tool list and zero offsets to start with (the operator data the
        service kept), else the configured ones."""
        machine, cycle_s, save = services.machine, services.cycle_s, services.save
        params = services.params
        self.workers = services.workers
        self._on_wait = services.on_wait
        self.alarms = services.alarms
        self.channel = channel
        self.config = config
        self._loader = services.loader
        self._exists = services.exists
        self._cycle_s = cycle_s
        self._deterministic = services.deterministic  # virtual clock: wait for the decoder
        self._files = services.files  # the output area's writer: queues, never blocks
        self.error_log_name = f"errors-ch{channel.channel_id}.log"
        self._axes = tuple(a.name for a in config.axes)
        self._axis_numbers = tuple(a.logical_number for a in config.axes)
        # the tool list and zero offsets the decoders read and the objects write
        self.tables = tables_from_config(machine) if tables is None else tables
        channel.tooling = initial_tooling(self.tables, len(config.axes))
        self._tools = self.tables.tools  # the radii, for decoders without modal tables
        self._params = params
        self._switchover = services.switchover
        self._buffer_blocks = config.look_ahead_blocks
        self._pending_start: tuple[Job, bool, bool] | None = None  # waits for the axes
        self._queued_jobs: list[Job] = []  # manual blocks sent while the start waits
        self._run: ChannelRun | None = None  # the run from its begin to its end
        # the execution mode in effect before a PROD_TIME run, in effect again at its end:
        # a machining time calculation is a simulation and leaves the channel as it was
        self._mode_before_prod_time = 0
        # the contour look-ahead log of the last program run (the PLC reads it after)
        self._contour: ContourLog | None = None
        self._internal_hold = False  # feedhold of a suspend_axis_output request
        self._waits_for_axes = False  # the last cycle's run (or start) waited for its axes
        self._modal: ModalState | None = None  # MDI: modal state carried between blocks
        self.time_s = 0.0  # kernel time of the cycle (PROD_TIME: the simulated time)
        # set by the kernel when a RESET of this channel is queued: a cycle waiting for
        # the decoder or the check (virtual clock) stops waiting; cleared by ``reset``
        self.reset_pending = threading.Event()
        self._check_max_errors = services.check_max_errors  # errors kept per check
        # the spindle's state and the unit are kept in the channel's parts (no copy)
        self.plc = PlcFunctions(config.techno, Spindle(config.techno.spindel, channel),
                                machine.plc, channel)
        self.touched = False  # the last cycle changed the channel's state
        # #MSG texts from the decoder thread (deque appends are thread-safe)
        self._messages: deque[str] = deque(maxlen=MESSAGES_LISTED)
        self._surroundings = Surroundings(
            write_file=lambda name, text, replace: save(name, text.encode(), replace),
            show_message=self._messages.append,
            hscs={mode.upper(): HscProgram(c.prog, c.tolerance / UM01_PER_MM)
                  for mode, c in config.hscs},
            kinematic_chain=config.kinematic_chain(),
            idle_steps_max=services.idle_steps_max,
            m_function_known=config.techno.m_known,
        )
        self.manual = ManualMode(channel, machine, params, cycle_s, self._move, self.report)

    def _move(self, event: ChannelEvent) -> None:
        """The channel's state changes only here, as ``TRANSITIONS`` says (an event the
        table does not allow raises ``TransitionNotAllowed``: a kernel bug)."""
        ch = self.channel
        ch.state = next_state(ch.state, event, ch.mode, bool(ch.program.program_name))

    # ------------------------------------------------------------ commands

    def select_mode(self, mode: int) -> Refusal | None:
        """Choose the operation mode (only while the channel is not working)."""
        ch = self.channel
        if mode not in SELECTABLE_MODES:
            names = ", ".join(f"{m.value} {m.name}" for m in sorted(SELECTABLE_MODES))
            return Refusal(RefusalReason.INVALID_VALUE,
                           f"mode {mode} cannot be selected; use {names}")
        if not allowed(ch.state, ChannelEvent.SELECT_MODE):
            return _not_ready(ch, "select a mode after the program ends or after RESET")
        ch.mode = ChannelMode(mode)  # one of SELECTABLE_MODES (checked above)
        self._move(ChannelEvent.SELECT_MODE)
        self.manual.publish()  # hb_display_r.state follows the mode
        if mode != ChannelMode.AUTOMATIC:
            ch.program = replace(ch.program, program_name="")
        self._modal = None
        return None

    def select_program(self, name: str) -> Refusal | None:
        """Select ``name`` from the program store: AUTOMATIC/READY."""
        ch = self.channel
        if ch.state == ChannelState.ERROR:
            return _not_ready(ch, f"cannot select {name!r} before RESET, which clears the error")
        if not allowed(ch.state, ChannelEvent.SELECT_PROGRAM):
            return _not_ready(ch, f"cannot select {name!r} while it works; hold and RESET first")
        if not name or not self._exists(name):
            return Refusal(RefusalReason.NOT_FOUND, f"no program {name!r} in the program store")
        ch.mode = ChannelMode.AUTOMATIC
        ch.program = replace(ch.program, program_name=name)
        self._move(ChannelEvent.SELECT_PROGRAM)
        return None

    def start(self) -> Refusal | None:
        """START: run the selected program, resume from HOLD, continue after a stop."""
        ch = self.channel
        if allowed(ch.state, ChannelEvent.RESUME):
            self._move(ChannelEvent.RESUME)
            ch.program = replace(ch.program, waiting_for_start=False)
            if self._run is not None:  # None: the start still waits for the axes
                self._run.resume()
            return None
        if ch.state == ChannelState.ACTIVE:
            if not ch.program.waiting_for_start:
                return _not_ready(ch, "the program is running already")
            moving = self.manual.program_motion()
            if moving is not None:
                return _not_ready(ch, f"axis {moving} still moves in manual mode (G200): "
                                  "release its jog key or wait, then START")
            self.manual.end_g200()  # "continue motion"
            ch.program = replace(ch.program, waiting_for_start=False)
            if self._run is not None:
                self._run.resume()  # M0/M1 or a single-block stop
            return None
        if ch.state != ChannelState.READY or ch.mode != ChannelMode.AUTOMATIC:
            return _not_ready(ch, "START needs AUTOMATIC/READY (select a program first) or HOLD")
        self._start_when_linked(Job(ch.program.program_name), keep_open=False, fresh_modal=True)
        return None

    def hold(self) -> Refusal | None:
        """Feedhold: decelerate on the path and stop (ACTIVE -> HOLD)."""
        ch = self.channel
        if ch.state != ChannelState.ACTIVE:
            return _not_ready(ch, "feedhold needs a running program (ACTIVE)")
        if self._run is not None and self._run.ignores_feedhold:
            return None  # a dry run (MACHINE_LOCK) ignores feedhold
        self._move(ChannelEvent.HOLD)
        if self.manual.engaged or self.manual.in_program:
            self.manual.feedhold()
        if self._run is not None:
            self._run.hold()
        return None

    def manual_block(self, text: str) -> Refusal | None:
        """MDI: run ``text`` as manual blocks (selects MDI when the channel is idle)."""
        ch = self.channel
        extended = bool(ch.program.execution_mode_active & ExecutionMode.ADD_MDI_BLOCK)
        if not text.strip():
            return Refusal(RefusalReason.INVALID_VALUE, "the manual block is empty")
        if ch.state == ChannelState.ACTIVE and ch.mode == ChannelMode.MDI and extended:
            job = Job(_MDI_NAME, text, manual=True)
            if isinstance(self._run, ProgramRun):
                self._run.add(job)  # continues the same program
            else:  # the first block still waits for the axes
                self._queued_jobs.append(job)
            return None
        # from an idle channel in any mode (MANUAL too, once no axis moves by hand): the
        # block selects MDI, as a new mode chosen at the HMI would
        if not allowed(ch.state, ChannelEvent.START):
            return _not_ready(ch, "a manual block needs a channel that is not working")
        if ch.mode != ChannelMode.MDI:
            ch.mode = ChannelMode.MDI
            ch.program = replace(ch.program, program_name="")
            self._modal = None
        extended = bool(ch.switches.execution_mode_command & ExecutionMode.ADD_MDI_BLOCK)
        self._start_when_linked(
            Job(_MDI_NAME, text, manual=True), keep_open=extended, fresh_modal=False
        )
        return None

    def _waiting(self) -> bool:
        """Called at each poll of a cycle that waits for the decoder or the check
        (virtual clock): the kernel answers the commands of the cycle; True once a RESET
        is queued (the wait ends, the RESET is applied at the next cycle)."""
        self._on_wait()
        return self.reset_pending.is_set()

    def reset(self) -> Refusal | None:
        """RESET from any state: stop at once, clear errors, back to READY or SELECTED."""
        ch = self.channel
        self.reset_pending.clear()
        self._drop_run()
        self.manual.stop_at_once()
        ch.program = replace(ch.program, decoder_flags=0, waiting_for_start=False)
        self._pending_start = None
        self._queued_jobs.clear()
        if self._contour is not None:
            self._contour.stop()
            show_contour_state(ch, self._contour)
        self._internal_hold = False
        self.plc.reset()
        ch.errors = ChannelErrors()
        self.alarms.reset_channel(ch.channel_id)  # ISG: RESET clears the channel's errors
        ch.path = ch.path._replace(path_velocity_mm_s=0.0, remaining_in_block_mm=0.0)
        for axis in ch.axes:
            axis.distance_to_go_01um = 0  # no block in the interpolator
        self._move(ChannelEvent.RESET)
        self._modal = None
        ch.tooling = after_reset(ch.tooling)
        self.initialise_channel()
        return None

    def initialise_channel(self) -> None:
        """Channel init (start-up, RESET): the configured axes are back in the channel,
        the command positions take the drives' positions (offsets cleared), and a
        jog-of-path channel checks that all its axes are clones (P-CHAN-00306)."""
        for axis in self.channel.axes:
            axis.released = False
            axis.offset_live = False
        self._switchover.adjust_to_drives(self.channel)
        self._check_jog_of_path()

    def jog_of_path_error(self) -> ErrorEntry | None:
        """None when the channel may work: not a jog-of-path channel, or all its axes
        in the channel are clones; otherwise the error naming the axis."""
        if not self.config.jog_of_path_only:
            return None
        for axis in self.channel.axes:
            if not axis.released and not self._params[axis.logical_number].cloned:
                return ErrorEntry(
                    AxisErrorId.JOG_OF_PATH_AXIS_NOT_CLONE,
                    f"axis {axis.name} (kopf.achs_nr {axis.logical_number}) of jog-of-path "
                    f"channel {self.channel.channel_id} is not a clone (jog_of_path_only, "
                    "P-CHAN-00306): configure it with kopf.clone_of",
                )
        return None

    def locked_axes(self) -> frozenset[int]:
        """Axes a program block must not move: P-AXIS-00277 set, not referenced."""
        return self.manual.locked_axes()

    def referenced(self, axes: tuple[int, ...]) -> None:
        """G74 homed the channel axes with these indices (a run reports it)."""
        for axis_index in axes:
            self.manual.mark_referenced(axis_index)

    @property
    def manual_offsets_mm(self) -> tuple[float, ...] | None:
        """The G200/G201 manual offsets the path's output adds (None: all 0)."""
        return self.manual.offsets_mm

    def manual_mode(self, request: ManualModeRequest) -> None:
        """The path reached a G200/G201/G202 block."""
        self.manual.program_request(request)

    def zero_offsets_written(self, writes: tuple[ZeroOffsetWrite, ...]) -> None:
        """The path reached the block after the program's ``V.G.NP`` writes."""
        apply_nc_zero_offsets(self.channel, self.tables, writes)

    def _check_jog_of_path(self) -> bool:
        """True when the channel may work; otherwise it goes to ERROR naming the axis."""
        error = self.jog_of_path_error()
        if error is not None:
            self._fail(error)
        return error is None

    def report(self, error: ErrorEntry) -> None:
        """List ``error`` (a warning leaves the channel's state alone)."""
        if error.warning:
            self.list_error(error)
        else:
            self._fail(error)

    # ------------------------------------------------------------ jog of path

    @property
    def axes_ready(self) -> bool:
        """The channel's output is not suspended and every axis in it is linked."""
        ch = self.channel
        if ch.suspend.output_suspended:
            return False
        for axis in ch.axes:
            if not axis.actual_link and not axis.released:
                return False
        return True

    @property
    def moving(self) -> bool:
        """The path is not at standstill."""
        return isinstance(self._run, ProgramRun) and self.channel.path.path_velocity_mm_s > 0.0

    def internal_hold(self) -> bool:
        """Brake the path for a suspend request (the channel stays ACTIVE); True when
        this started the feedhold."""
        if self._internal_hold or not isinstance(self._run, ProgramRun):
            return False
        self._internal_hold = True
        self._run.executor.hold()
        return True

    def release_internal_hold(self) -> bool:
        """End the internal feedhold (a HOLD the operator commanded stays); True when
        one was active."""
        if not self._internal_hold:
            return False
        self._internal_hold = False
        if isinstance(self._run, ProgramRun) and self.channel.state != ChannelState.HOLD:
            self._run.executor.release_hold()
        return True

    # ------------------------------------------------------------ run begins

    def _start_when_linked(self, job: Job, keep_open: bool, fresh_modal: bool) -> None:
        """Program start: the configured axes are back in the channel; the run begins
        in the first cycle all of them are linked (at once when they are)."""
        ch = self.channel
        for axis in ch.axes:
            axis.released = False
        self._move(ChannelEvent.START)
        ch.program = replace(  # ISG: the skip levels are read at program start
            ch.program, waiting_for_start=False,
            block_ignore_active=ch.switches.block_ignore_commanded)
        ch.errors = ChannelErrors()
        self._pending_start = (job, keep_open, fresh_modal)
        if self.axes_ready or self._checks_only(job):
            self._begin_pending()

    def _checks_only(self, job: Job) -> bool:
        """The run is a syntax check or dry run: it needs no axis output (it starts and
        runs while the output is suspended)."""
        mode = self.channel.switches.execution_mode_commanded
        return (not job.manual and bool(mode & _CHECK_MODES)
                and not mode & ExecutionMode.PROD_TIME)

    def _begin_pending(self) -> None:
        assert self._pending_start is not None
        job, keep_open, fresh_modal = self._pending_start
        self._pending_start = None
        if not self._check_jog_of_path():
            return
        # Position adjustment: the channel starts where the physical axes are.
        self._switchover.adjust_to_drives(self.channel)
        self._begin(job, keep_open, fresh_modal)

    def _active_mode(self) -> int:
        """The commanded execution mode as it takes effect at this start: SYNCHK implies
        MACHINE_LOCK (warning 21309 when it was not commanded) and SUPPRESS_TECHNO_OUTPUT."""
        mode = self.channel.switches.execution_mode_commanded
        if mode & ExecutionMode.SYNCHK:
            if not mode & ExecutionMode.MACHINE_LOCK:
                self.list_error(ErrorEntry(
                    SYNCHK_WITHOUT_MACHINE_LOCK, "syntax check (SYNCHK) without MACHINE_LOCK: "
                    "MACHINE_LOCK is set implicitly, the axes do not move", warning=True))
            mode |= ExecutionMode.MACHINE_LOCK | ExecutionMode.SUPPRESS_TECHNO_OUTPUT
        return mode

    def _begin(self, job: Job, keep_open: bool, fresh_modal: bool) -> None:
        ch = self.channel
        mode: int
        if job.manual:  # the simulation modes act on programs; manual blocks run as usual
            mode = ch.switches.execution_mode_commanded & ~_PROGRAM_MODES
        else:
            mode = self._active_mode()
        if not job.manual and mode & ExecutionMode.PROD_TIME:
            self._mode_before_prod_time = ch.program.execution_mode_active
        ch.program = replace(ch.program, execution_mode_active=mode, decoder_flags=0)
        if not job.manual and mode & _CHECK_MODES and not mode & ExecutionMode.PROD_TIME:
            self._begin_check(job, mode)
            return
        dynamics, sw_limits = self._axis_limits()
        self.manual.clear_program()  # a run starts where the axes stand
        position = tuple(a.position_mm for a in ch.axes)
        kinematics = self._path_kinematics(sw_limits, dynamics)
        trafo = None
        if fresh_modal or self._modal is None:
            self._modal = self.new_modal(position)
        else:
            self._modal.position_mm = position
            if self._modal.settings.trafo and kinematics is not None:
                # a manual block after one that left #TRAFO ON: it goes on in the
                # programmed coordinates
                tool = self._modal.tool_offset
                trafo = TrafoUse(self._modal.tooling.tools.length_mm(tool) if tool else 0.0)
                position = kinematics.program_of(position, trafo.tool_length_mm)
                self._modal.position_mm = position
        feed = DecoderFeed(
            channel_id=ch.channel_id, axes=self._axes, loader=self._loader, tools=self._tools,
            modal=self._modal, capacity=self._buffer_blocks + _FEED_MARGIN_BLOCKS,
            keep_open=keep_open, axis_numbers=self._axis_numbers,
            contour_lookahead=self.config.contour_lookahead, surroundings=self._surroundings,
            section_planner=partial(plan_section, dynamics=dynamics,
                                    buffer_blocks=self._buffer_blocks, cycle_s=self._cycle_s),
            interrupted=self._waiting, workers=self.workers,
            skip_levels=ch.program.block_ignore_active,
        )
        feed.add(job)
        for more in self._queued_jobs:
            feed.add(more)
        self._queued_jobs.clear()
        if not keep_open:
            feed.finish()
        executor = PathExecutor(
            dynamics, position, cycle_s=self._cycle_s, buffer_blocks=self._buffer_blocks,
            sw_limits_mm=None if trafo is not None else sw_limits,
        )
        prod_time = not job.manual and bool(mode & ExecutionMode.PROD_TIME)
        # the machining time calculation runs through without stops
        executor.single_block = ch.switches.single_block and not prod_time
        self._modal.contour_log_area = LogArea.NONE  # as the new log: no marked area yet
        contour = None
        if self.config.contour_lookahead:  # the log is cleared at every program start
            contour = self._contour = ContourLog(self.config.contour_lookahead_log_max,
                                                 self._buffer_blocks)
        if prod_time:
            trace = None
            if ch.switches.prod_time_trace:
                trace = ProdTimeTrace(job.name, ch.channel_id, self._axes, self._cycle_s)
                trace.record(0.0, position, 0.0, 0.0, 0.0, 0)
            self._run = ProdTimeRun(
                self, ch, feed, executor, contour, started_at_s=self.time_s,
                buffer_blocks=self._buffer_blocks, deterministic=self._deterministic,
                cycle_s=self._cycle_s, trace=trace, kinematics=kinematics, trafo=trafo)
        else:
            self._run = ProgramRun(
                self, ch, feed, executor, contour, started_at_s=self.time_s,
                buffer_blocks=self._buffer_blocks, deterministic=self._deterministic,
                kinematics=kinematics, trafo=trafo)
        if contour is not None:
            show_contour_state(ch, contour)
        self._show_start(job)  # state, errors: set by _start_when_linked

    def new_modal(self, position_mm: tuple[float, ...]) -> ModalState:
        """The modal state a run starts with: the channel's look-ahead defaults and
        cycle time (METB must exceed it)."""
        la = self.config.la
        defaults = LookAheadMark(metb_s=la.metb_s, vfbt=la.vfbt, bbtrc=la.bbtrc)
        modal = ModalState(position_mm=position_mm, look_ahead_defaults=defaults,
                           look_ahead_params=defaults, cycle_s=self._cycle_s,
                           homing=self.manual.homing_table())
        feed_mm_min = self.config.prog_start.feedrate  # P-CHAN-00099: F of a block without F
        if feed_mm_min > 0.0:
            modal.feed_mm_min = feed_mm_min
        seed_modal(modal, self.tables, self.channel.tooling)
        stored_rpm = self.plc.spindle.state.programmed_rpm  # S is stored across runs (ISG)
        if stored_rpm > 0.0:
            modal.spindle_speed_rpm = stored_rpm  # M19 needs a speed > 0 set
        return modal

    def _show_start(self, job: Job) -> None:
        """What a run or check shows at its start: counters at 0, the job's file; a
        program also starts with no messages and default high-speed settings."""
        ch = self.channel
        ch.block = ch.block._replace(file_name=job.name, line=0, file_offset=0,
                                     block_number=-1, block_count=0)
        ch.path = ch.path._replace(dist_prog_start_01um=0.0, program_time_s=0.0)
        if not job.manual:
            self._messages.clear()
            ch.program = replace(ch.program, messages=(), message_count=0,
                                 machining=MachiningSettings())

    def show_decoder_state(self) -> None:
        """The #MSG texts and the #HSC/G133/.. settings the decoder reached."""
        ch = self.channel
        new = []
        while self._messages:
            new.append(self._messages.popleft())
        if new:
            ch.program = replace(
                ch.program,
                messages=(tuple(reversed(new)) + ch.program.messages)[:MESSAGES_LISTED],
                message_count=ch.program.message_count + len(new))
        if self._modal is not None and self._modal.settings != ch.program.machining:
            ch.program = replace(ch.program, machining=replace(self._modal.settings))

    def _axis_limits(self) -> tuple[tuple[AxisDynamics, ...], tuple[tuple[float, float], ...]]:
        """Dynamics and software limits of the channel's axes from the effective axis
        parameters (read at each start, so an update applies from the next run)."""
        params = [self._params[n] for n in self._axis_numbers]
        dynamics = tuple(
            AxisDynamics(p.vel_max_mm_s, p.acc_max_mm_s2, p.vel_jump_mm_s) for p in params
        )
        # P-AXIS-00705: by default an axis's limits count once it is referenced
        return dynamics, tuple(monitored_limits_mm(p, self.manual.referenced(k))
                               for k, p in enumerate(params))

    def _path_kinematics(self, sw_limits: tuple[tuple[float, float], ...],
                         dynamics: tuple[AxisDynamics, ...]) -> PathKinematics | None:
        """The channel's kinematics for a run (None: a three-axis channel)."""
        chain = self._surroundings.kinematic_chain
        if chain is None:
            return None
        x, y, z = (self._axes.index(name) for name in "XYZ")
        return PathKinematics(chain, (x, y, z), sw_limits, self._axes,
                              tuple(d.vel_max_mm_s for d in dynamics))

    def _begin_check(self, job: Job, mode: int) -> None:
        """Start the syntax check (SYNCHK) or dry run (MACHINE_LOCK) of the program."""
        ch = self.channel
        dynamics, sw_limits = self._axis_limits()
        synchk = bool(mode & ExecutionMode.SYNCHK)
        check = CheckRun(
            channel_id=ch.channel_id, name=job.name, text_of=self._loader, axes=self._axes,
            axis_numbers=self._axis_numbers, tools=self._tools,
            contour_lookahead=self.config.contour_lookahead,
            start_mm=tuple(a.position_mm for a in ch.axes),
            dynamics=dynamics, sw_limits_mm=sw_limits,
            settings=ch.switches.syn_chk if synchk else None, single_step=ch.switches.single_block,
            deterministic=self._deterministic, files=self._files,
            surroundings=self._surroundings,
            modal=self.new_modal(tuple(a.position_mm for a in ch.axes)),
            max_errors=self._check_max_errors, interrupted=self._waiting,
            workers=self.workers,
        )
        self._run = ChannelCheck(self, ch, check, started_at_s=self.time_s,
                                 deterministic=self._deterministic)
        ch.program = replace(ch.program,
                             decoder_flags=DecoderFlag.SYNTAX_CHECK if synchk else 0)
        self._show_start(job)

    # ------------------------------------------------------------ cycle

    def cycle(self, time_s: float) -> bool:
        """One GEO cycle of the channel; True while it has motion, decoding or a
        spindle ramp to do."""
        busy = self._run_cycle(time_s)
        if show_technology(self.plc, time_s, self._cycle_s):
            self.touched = True
            busy = True
        reason = self._wait_reason()
        if reason != self.channel.wait_reason:
            self.channel.wait_reason = reason
            self.touched = True
        return busy

    def _wait_reason(self) -> int:
        """Why the channel stands after this cycle (``wait_reason``); the running
        channel's case first, kept short (it is every cycle's)."""
        ch, run = self.channel, self._run
        if ch.state == _ACTIVE and not (self._waits_for_axes or self._internal_hold):
            return _NOT_WAITING if run is None else run.wait_reason()
        return channel_wait_reason(
            ch, _NOT_WAITING if run is None else run.wait_reason(),
            axes_missing=self._waits_for_axes, internal_hold=self._internal_hold)

    def cruise_budget(self, most: int) -> int | None:
        """How many of the next cycles (at most ``most``) of this channel may be run
        through ``cruise`` (one stepped cycle, or a bulk): None when its cycles change
        nothing (no run, the technology at rest), else what its program run's cruise
        allows (0: the next cycle must be run as a cycle, ``cycle``)."""
        plc, ch = self.plc, self.channel
        if (not plc.spindle.reached
                or any(u.pending and u.ack_due_s is not None for u in plc.unit.units)
                or plc.stops_due):
            return 0  # a ramp or an acknowledge runs in time, an MVS_SNS stop goes
        if ch.state not in WORKING_STATES:
            return None
        run = self._run
        if (self.manual.engaged or self.manual.in_program or self._pending_start is not None
                or self._waits_for_axes or not self.axes_ready
                or not isinstance(run, ProgramRun)):
            return 0  # (the last cycle waited for the axes: this one's wait reason changes)
        return run.cruise_budget(most)

    def cruise(self, cycles: int, time_s: float) -> None:
        """Run ``cycles`` cycles that ``cruise_budget`` allowed, the last at ``time_s``
        (a channel whose cycles change nothing only takes the time): what ``cycle``
        would do in each, as the budget's conditions hold (technology at rest, wait
        reason unchanged)."""
        self.time_s = time_s
        run = self._run
        if self.channel.state in WORKING_STATES:
            assert isinstance(run, ProgramRun)
            run.cruise(cycles, time_s)
            self.touched = True

    def _run_cycle(self, time_s: float) -> bool:
        self.time_s = time_s
        ch = self.channel
        self._waits_for_axes = False
        if ch.state not in WORKING_STATES:
            self.touched = False
            return False
        if self.manual.engaged and self._run is None:  # jog, handwheel, homing (MANUAL)
            self.touched = True
            return self.manual.cycle()
        run = self._run
        if not self.axes_ready and not isinstance(run, ChannelCheck):
            # suspended, or a link waits
            self._waits_for_axes = True
            if isinstance(run, ProdTimeRun) and self._pending_start is None:
                run.wait_for_link()  # a real run's time runs on while a link waits
            self.touched = False
            return False
        if self._pending_start is not None:
            self._begin_pending()
            run = self._run
        self.touched = True
        if run is None:  # the start failed (jog of path)
            return False
        # G200/G201: the manual motions move their offsets before the path's step
        manual_moving = self.manual.in_program and self.manual.offset_cycle()
        match run.cycle(time_s):
            case Step.BUSY:
                return True
            case Step.WAITING:
                return manual_moving
            case Step.ENDED:
                self._end_program()
            case Step.FAILED:
                assert run.failure is not None
                self._fail(run.failure)
            case Step.PAUSED:
                self._move(ChannelEvent.CHECK_PAUSE)
                ch.program = replace(ch.program, waiting_for_start=True)
        return False

    # ------------------------------------------------------------ run ends

    def _drop_run(self) -> ChannelRun | None:
        """End the run at once; the modal state it reached carries on (MDI). A PROD_TIME
        run puts back the execution mode that was in effect before it."""
        run, self._run = self._run, None
        self.manual.clear_program()  # the axes stand where path and manual offset put them
        if isinstance(run, ProdTimeRun):
            self.channel.program = replace(self.channel.program,
                                           execution_mode_active=self._mode_before_prod_time)
        if run is not None:
            modal = run.cancel()
            if modal is not None and self._modal is not None:
                self._modal = modal
        return run

    def _end_program(self) -> None:
        ch = self.channel
        run = self._drop_run()
        if self._contour is not None and not self._contour.complete:
            # M30 reached before the end of the data was taken: what a loop held back
            # is logged now
            if self._contour.end_of_data():
                self.list_error(log_full_warning(self._contour, ch.block.file_name))
            show_contour_state(ch, self._contour)
        self._move(ChannelEvent.PROGRAM_END)
        ch.program = replace(ch.program, waiting_for_start=False)
        ch.path = ch.path._replace(path_velocity_mm_s=0.0, remaining_in_block_mm=0.0)
        self._ended(run, "READY")

    def _fail(self, error: ErrorEntry) -> None:
        ch = self.channel
        self.list_error(error)
        run = self._drop_run()
        if self._contour is not None:  # nothing more of the area will be read in
            self._contour.stop()
            show_contour_state(ch, self._contour)
        self._move(ChannelEvent.FAIL)
        # the program is aborted (ISG reaction class 2): what it output waits for
        # nobody, and the spindle stops as the path did (docs/manual.md)
        self.plc.reset()
        ch.program = replace(ch.program, waiting_for_start=False)
        self._ended(run, f"ERROR {error.id}")

    def _ended(self, run: ChannelRun | None, how: str) -> None:
        """The program time of the run that ended; a traced PROD_TIME run's rows go to
        the output area (``how``: its last row)."""
        if run is None:
            return
        self.channel.path = self.channel.path._replace(
            program_time_s=self.time_s - run.started_at_s)
        if isinstance(run, ProdTimeRun):
            run.write_trace(how, self._files)

    def list_error(self, error: ErrorEntry, to_log: bool = True,
                   keep_last: bool = False, alarm_class: AlarmClass | None = None) -> None:
        """List ``error`` and raise it as an alarm; ``to_log``: also in the channel's
        error log file (not the findings of a syntax check, which may be thousands: they
        go to dec0<c>.sc); ``keep_last``: leave the last slot free (for the error or
        warning that ends a check); ``alarm_class``: when not the one of its id."""
        ch = self.channel
        self.alarms.raise_error(error, ch.channel_id, alarm_class)
        if to_log:
            log.info("channel %d: %s", ch.channel_id, error)
            self._files(self.error_log_name, f"{self.time_s:.3f} s {error}\n".encode())
        listed = ch.errors.entries
        if len(listed) < ERRORS_LISTED - keep_last:
            listed = (*listed, error)
        ch.errors = ChannelErrors(listed, ch.errors.count + 1)

    # ------------------------------------------------------------ contour look-ahead

    def answer_contour_request(self) -> None:
        """The PLC set the semaphore: fill the response from the log (mode 1) or the
        recent elements (mode 2), then reset the semaphore."""
        unit = self.channel.contour
        response = () if self._contour is None else self._contour.answer(
            unit.request_start_position, unit.request_length)
        self.channel.contour = replace(unit, response=response, semaphor=False)
