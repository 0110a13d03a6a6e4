"""One channel at work: its mode/state machine, its program run, its path.

The GEO cycle calls ``ChannelRunner.cycle`` once per cycle; commands (select, start,
feedhold, RESET, manual block) call the other methods, also on the cycle thread, and
answer None or a ``Refusal`` with the reason. The decoder of a run lives in the run's
SDA thread (``DecoderFeed``); blocks enter the look-ahead buffer of the
``PathExecutor`` as slots free up.

Errors take effect where they are in the program: the blocks before an erroneous block
run to their end, the path stops there, and the channel goes to ERROR with the error
(id, text, file, line, column) in its error list. A block that would leave a software
limit is refused before it moves.
"""

from __future__ import annotations

import logging
import threading
import time
from collections import deque
from collections.abc import Callable
from dataclasses import replace
from functools import partial

from ..config import ChannelConfig, MachineConfig
from .axis_params import AxisErrorId, AxisParameters
from .channel_mode import (
    IDLE_STATES,
    SELECTABLE_MODES,
    ChannelMode,
    ChannelState,
    describe,
)
from .commands import Refusal, RefusalReason
from .contour_lookahead import LOG_FULL_WARNING, ContourLog
from .decoder_feed import DecodeEnd, DecoderFeed, Job
from .nc import ModalState, NcError
from .nc.blocks import (
    AxisExchange,
    AxisExchangeKind,
    Block,
    ContourKind,
    LogArea,
    LookAheadMark,
    SourceRef,
    StopKind,
)
from .nc.contour import LOOP_MARKERS
from .nc.technology import HscProgram, MachiningSettings, Surroundings
from .path.errors import PathErrorId
from .path.executor import AxisDynamics, PathError, PathExecutor
from .path.interpolator import Waiting
from .path.section_plan import plan_section
from .path.segments import Segment
from .prod_time_trace import ProdTimeTrace, trace_file_name
from .state import MESSAGES_KEPT, Channel, ChannelError, DecoderFlag, ExecutionMode
from .switchover import Switchover
from .syntax_check import SYNCHK_WITHOUT_MACHINE_LOCK, CHECK_STOPPED_WARNING, CheckRun, Pause

log = logging.getLogger(__name__)

MAX_ERRORS_KEPT = 8  # the error list keeps the first errors of a run (the first is the cause)
_FEED_MARGIN_BLOCKS = 256  # the decoder may run this far ahead of the look-ahead buffer
_MDI_NAME = "MDI"  # file name of manual blocks in errors and objects
_INCR_PER_MM = 10_000  # 0.1 um increments per mm
PROD_TIME_STEPS_PER_CYCLE = 5_000  # virtual clock: simulated cycles per GEO cycle (PROD_TIME)
_PROD_TIME_SHARE = 0.4  # realtime clock: share of a GEO cycle the calculation may use
_CHECK_MODES = ExecutionMode.SYNCHK | ExecutionMode.MACHINE_LOCK
_PROGRAM_MODES = _CHECK_MODES | ExecutionMode.PROD_TIME | ExecutionMode.SUPPRESS_TECHNO_OUTPUT


def _not_ready(channel: Channel, what: str) -> Refusal:
    return Refusal(
        RefusalReason.NOT_READY,
        f"channel {channel.channel_id} is {describe(channel.mode, channel.state)}: {what}",
    )


class ChannelRunner:
    """The working parts of one channel, driven by the GEO cycle."""

    def __init__(
        self,
        channel: Channel,
        config: ChannelConfig,
        machine: MachineConfig,
        loader: Callable[[str], str],
        exists: Callable[[str], bool],
        cycle_s: float,
        deterministic: bool,
        files: Callable[..., None] = lambda name, data, replace=False: None,
        *,
        params: dict[int, AxisParameters],
        switchover: Switchover,
    ) -> None:
        """``params`` are the kernel's effective axis parameters (read at each program
        start, so a parameter update applies from the next run); ``switchover`` links
        the channel's axes to the drives."""
        self.channel = channel
        self.config = config
        self._loader = loader
        self._exists = exists
        self._cycle_s = cycle_s
        self._deterministic = deterministic  # virtual clock: wait for the decoder
        self._files = files  # appends to a file of the program store, off this thread
        self.error_log_name = f"errors-ch{channel.channel_id}.log"
        self._axes = tuple(a.name for a in config.axes)
        self._axis_numbers = tuple(a.logical_number for a in config.axes)
        self._tools = {t.d: t.radius_mm for t in machine.tools}
        self._params = params
        self._switchover = switchover
        self._buffer_blocks = config.look_ahead_blocks
        self._pending_start: tuple[Job, bool, bool] | None = None  # waits for the axes
        self._queued_jobs: list[Job] = []  # manual blocks sent while the start waits
        # a block that waits for standstill (axis exchange, LOG CLEAR: flush and wait)
        self._sync: Block | None = None
        self._backlog: list = []  # decoded items that came after it
        self._contour: ContourLog | None = None  # contour look-ahead of the run
        self._contour_changed = False  # blocks were prepared: show the unit's new state
        self._internal_hold = False  # feedhold of a suspend_axis_output request
        self._executor: PathExecutor | None = None
        self._feed: DecoderFeed | None = None
        self._last_pushed: Block | None = None  # the block that entered the buffer last
        self._buffer_warned = False  # BUFFER_LIMITS_SPEED shown in this run
        self._modal: ModalState | None = None  # MDI: modal state carried between blocks
        self._pending_error: ChannelError | None = None
        self._fed_all = False
        self._started_at_s = 0.0
        self._time_s = 0.0
        self._check: CheckRun | None = None  # syntax check or dry run of the program
        # set by the kernel when a RESET of this channel is queued: a cycle waiting for
        # the decoder or the check (virtual clock) stops waiting; cleared by ``reset``
        self.reset_pending = threading.Event()
        self._check_max_errors = machine.limits.check_max_errors  # errors kept per check
        self._check_left_out = 0  # errors of the check counted but not kept, shown so far
        self._released: Pause = Pause.NONE  # START ended this pause (flag for one cycle)
        self._prod_time = False  # PROD_TIME: the run is simulated, no axis moves
        self._sim_steps = 0  # PROD_TIME: cycles simulated so far
        self._trace: ProdTimeTrace | None = None  # PROD_TIME with ch<c>.prod_time_trace
        self.touched = False  # the last cycle changed the channel's state
        # #MSG texts from the decoder thread (deque appends are thread-safe)
        self._messages: deque[str] = deque(maxlen=MESSAGES_KEPT)
        self._surroundings = Surroundings(
            write_file=lambda name, text, replace: files(name, text.encode(), replace=replace),
            show_message=self._messages.append,
            hscs={mode.upper(): HscProgram(c.prog, c.tolerance * 1e-4)  # 0.1 um -> mm
                  for mode, c in config.hscs},
            kinematics=False,  # this kernel configures no kinematic transformation
        )

    # ------------------------------------------------------------ commands

    def select_mode(self, mode: int) -> Refusal | None:
        """Choose the operation mode (only while the channel is not working)."""
        ch = self.channel
        if mode not in SELECTABLE_MODES:
            names = ", ".join(f"{m.value} {m.name}" for m in sorted(SELECTABLE_MODES))
            return Refusal(RefusalReason.INVALID_VALUE, f"mode {mode} cannot be selected; use {names}")
        if ch.state not in IDLE_STATES:
            return _not_ready(ch, "select a mode after the program ends or after RESET")
        ch.mode = mode
        ch.state = ChannelState.DESELECTED if mode == ChannelMode.STANDBY else ChannelState.SELECTED
        if mode != ChannelMode.AUTOMATIC:
            ch.program_name = ""
        self._modal = None
        return None

    def select_program(self, name: str) -> Refusal | None:
        """Select ``name`` from the program store: AUTOMATIC/READY."""
        ch = self.channel
        if ch.state == ChannelState.ERROR:
            return _not_ready(ch, f"cannot select {name!r} before RESET, which clears the error")
        if ch.state not in IDLE_STATES:
            return _not_ready(ch, f"cannot select {name!r} while it works; hold and RESET first")
        if not name or not self._exists(name):
            return Refusal(RefusalReason.NOT_FOUND, f"no program {name!r} in the program store")
        ch.mode, ch.state, ch.program_name = ChannelMode.AUTOMATIC, ChannelState.READY, name
        return None

    def start(self) -> Refusal | None:
        """START: run the selected program, resume from HOLD, continue after a stop."""
        ch = self.channel
        if ch.state == ChannelState.HOLD:
            ch.state = ChannelState.ACTIVE
            ch.waiting_for_start = False
            if self._check is not None:  # continue decoding (after an error, a step, STOP)
                self._released = self._check.pause
                self._check.resume()
            elif self._executor is not None:
                self._executor.resume()
            return None
        if ch.state == ChannelState.ACTIVE:
            if not ch.waiting_for_start:
                return _not_ready(ch, "the program is running already")
            ch.waiting_for_start = False
            self._executor.resume()
            return None
        if ch.state != ChannelState.READY or ch.mode != ChannelMode.AUTOMATIC:
            return _not_ready(ch, "START needs AUTOMATIC/READY (select a program first) or HOLD")
        self._start_when_linked(Job(ch.program_name), keep_open=False, fresh_modal=True)
        return None

    def hold(self) -> Refusal | None:
        """Feedhold: decelerate on the path and stop (ACTIVE -> HOLD)."""
        ch = self.channel
        if ch.state != ChannelState.ACTIVE:
            return _not_ready(ch, "feedhold needs a running program (ACTIVE)")
        if self._check is not None and self._check.settings is None:
            return None  # a dry run (MACHINE_LOCK) ignores feedhold
        ch.state = ChannelState.HOLD
        if self._check is not None:  # STOP acts on decoding
            self._check.stop()
        elif self._executor is not None and not self._prod_time:
            self._executor.hold()
        return None

    def manual_block(self, text: str) -> Refusal | None:
        """MDI: run ``text`` as manual blocks (selects MDI when the channel is idle)."""
        ch = self.channel
        extended = bool(ch.execution_mode_active & ExecutionMode.ADD_MDI_BLOCK)
        if not text.strip():
            return Refusal(RefusalReason.INVALID_VALUE, "the manual block is empty")
        if ch.state == ChannelState.ACTIVE and ch.mode == ChannelMode.MDI and extended:
            job = Job(_MDI_NAME, text, manual=True)
            if self._feed is None:  # the first block still waits for the axes
                self._queued_jobs.append(job)
            else:
                self._feed.add(job)  # continues the same program
            return None
        if ch.state not in IDLE_STATES or ch.mode == ChannelMode.MANUAL:
            return _not_ready(ch, "a manual block needs a channel that is not working")
        if ch.mode != ChannelMode.MDI:
            ch.mode = ChannelMode.MDI
            ch.program_name = ""
            self._modal = None
        extended = bool(ch.execution_mode_command & ExecutionMode.ADD_MDI_BLOCK)
        self._start_when_linked(
            Job(_MDI_NAME, text, manual=True), keep_open=extended, fresh_modal=False
        )
        return None

    def reset(self) -> Refusal | None:
        """RESET from any state: stop at once, clear errors, back to READY or SELECTED."""
        ch = self.channel
        self.reset_pending.clear()
        self._stop_run()
        if self._check is not None:
            self._check.cancel()
            self._check = None
        self._prod_time = False
        ch.decoder_flags = 0
        if self._executor is not None:
            self._executor.stop_now()
        self._pending_error = None
        self._pending_start = self._sync = None
        self._queued_jobs.clear()
        self._backlog = []
        if self._contour is not None:
            self._contour.stop()
            self._show_contour_state()
        self._internal_hold = False
        ch.errors, ch.error_count = (), 0
        ch.waiting_for_start = False
        ch.path_velocity_mm_s = ch.remaining_in_block_mm = 0.0
        if ch.mode == ChannelMode.STANDBY:
            ch.state = ChannelState.DESELECTED
        elif ch.mode == ChannelMode.AUTOMATIC and ch.program_name:
            ch.state = ChannelState.READY
        else:
            ch.state = ChannelState.SELECTED
        self._modal = None
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

    def _check_jog_of_path(self) -> bool:
        """True when the channel may work: not a jog-of-path channel, or all its axes in
        the channel are clones; otherwise the channel goes to ERROR naming the axis."""
        if not self.config.jog_of_path_only:
            return True
        for axis in self.channel.axes:
            if not axis.released and not self._params[axis.logical_number].cloned:
                self._fail(ChannelError(
                    AxisErrorId.JOG_OF_PATH_AXIS_NOT_CLONE,
                    f"axis {axis.name} (kopf.achs_nr {axis.logical_number}) of jog-of-path "
                    f"channel {self.channel.channel_id} is not a clone (jog_of_path_only, "
                    "P-CHAN-00306): configure it with kopf.clone_of",
                ))
                return False
        return True

    def report(self, error: ChannelError) -> None:
        """List ``error`` (a warning leaves the channel's state alone)."""
        if error.warning:
            self._raise(error)
        else:
            self._fail(error)

    # ------------------------------------------------------------ jog of path

    @property
    def axes_ready(self) -> bool:
        """The channel's output is not suspended and every axis in it is linked."""
        ch = self.channel
        if ch.output_suspended:
            return False
        for axis in ch.axes:
            if not axis.actual_link and not axis.released:
                return False
        return True

    @property
    def moving(self) -> bool:
        """The path is not at standstill."""
        return self._executor is not None and self.channel.path_velocity_mm_s > 0.0

    def internal_hold(self) -> bool:
        """Brake the path for a suspend request (the channel stays ACTIVE); True when
        this started the feedhold."""
        if self._internal_hold or self._executor is None:
            return False
        self._internal_hold = True
        self._executor.hold()
        return True

    def release_internal_hold(self) -> bool:
        """End the internal feedhold (a HOLD the operator commanded stays); True when
        one was active."""
        if not self._internal_hold:
            return False
        self._internal_hold = False
        if self._executor is not None and self.channel.state != ChannelState.HOLD:
            self._executor.release_hold()
        return True

    # ------------------------------------------------------------ run

    def _start_when_linked(self, job: Job, keep_open: bool, fresh_modal: bool) -> None:
        """Program start: the configured axes are back in the channel; the run begins
        in the first cycle all of them are linked (at once when they are)."""
        ch = self.channel
        for axis in ch.axes:
            axis.released = False
        ch.state = ChannelState.ACTIVE
        ch.waiting_for_start = False
        ch.errors, ch.error_count = (), 0
        self._pending_start = (job, keep_open, fresh_modal)
        if self.axes_ready or self._checks_only(job):
            self._begin_pending()

    def _checks_only(self, job: Job) -> bool:
        """The run is a syntax check or dry run: it needs no axis output (it starts and
        runs while the output is suspended)."""
        mode = self.channel.execution_mode_commanded
        return (not job.manual and bool(mode & _CHECK_MODES)
                and not mode & ExecutionMode.PROD_TIME)

    def _begin_pending(self) -> None:
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
        mode = self.channel.execution_mode_commanded
        if mode & ExecutionMode.SYNCHK:
            if not mode & ExecutionMode.MACHINE_LOCK:
                self._raise(ChannelError(
                    SYNCHK_WITHOUT_MACHINE_LOCK, "syntax check (SYNCHK) without MACHINE_LOCK: "
                    "MACHINE_LOCK is set implicitly, the axes do not move", warning=True))
            mode |= ExecutionMode.MACHINE_LOCK | ExecutionMode.SUPPRESS_TECHNO_OUTPUT
        return mode

    def _begin(self, job: Job, keep_open: bool, fresh_modal: bool) -> None:
        ch = self.channel
        if job.manual:  # the simulation modes act on programs; manual blocks run as usual
            mode = ch.execution_mode_commanded & ~_PROGRAM_MODES
        else:
            mode = self._active_mode()
        ch.execution_mode_active = mode
        self._prod_time = False
        ch.decoder_flags = 0
        if not job.manual and mode & _CHECK_MODES and not mode & ExecutionMode.PROD_TIME:
            self._begin_check(job, mode)
            return
        dynamics, sw_limits = self._axis_limits()
        position = tuple(a.position_mm for a in ch.axes)
        if fresh_modal or self._modal is None:
            self._modal = self.new_modal(position)
        else:
            self._modal.position_mm = position
        self._feed = DecoderFeed(
            channel_id=ch.channel_id, axes=self._axes, loader=self._loader, tools=self._tools,
            modal=self._modal, capacity=self._buffer_blocks + _FEED_MARGIN_BLOCKS,
            keep_open=keep_open, axis_numbers=self._axis_numbers,
            contour_lookahead=self.config.contour_lookahead, surroundings=self._surroundings,
            section_planner=partial(plan_section, dynamics=dynamics,
                                    buffer_blocks=self._buffer_blocks, cycle_s=self._cycle_s),
            interrupted=self.reset_pending.is_set,
        )
        self._last_pushed = None
        self._buffer_warned = False
        self._feed.add(job)
        for more in self._queued_jobs:
            self._feed.add(more)
        self._queued_jobs.clear()
        if not keep_open:
            self._feed.finish()
        self._executor = PathExecutor(
            dynamics, position, cycle_s=self._cycle_s,
            buffer_blocks=self._buffer_blocks, sw_limits_mm=sw_limits,
        )
        self._prod_time = not job.manual and bool(mode & ExecutionMode.PROD_TIME)
        self._sim_steps = 0
        self._trace = None
        if self._prod_time and ch.prod_time_trace:
            self._trace = ProdTimeTrace(job.name, ch.channel_id, self._axes, self._cycle_s)
            self._trace.record(0.0, position, 0.0, 0.0, 0.0, 0)
        # the machining time calculation runs through without stops
        self._executor.single_block = ch.single_block and not self._prod_time
        self._sync, self._backlog = None, []
        self._modal.contour_log_area = LogArea.NONE  # as the new log: no marked area yet
        if self.config.contour_lookahead:  # the log is cleared at every program start
            self._contour = ContourLog(self.config.contour_lookahead_log_max,
                                       self._buffer_blocks)
            self._executor.on_prepared = self._prepared
            self._show_contour_state()
        self._fed_all = False
        self._pending_error = None
        self._started_at_s = self._time_s  # state, errors: set by _start_when_linked
        self._show_start(job)

    def new_modal(self, position_mm: tuple[float, ...]) -> ModalState:
        """The modal state a run starts with: the channel's look-ahead defaults and
        cycle time (METB must exceed it)."""
        la = self.config.la
        defaults = LookAheadMark(metb_s=la.metb_s, vfbt=la.vfbt, bbtrc=la.bbtrc)
        return ModalState(position_mm=position_mm, look_ahead_defaults=defaults,
                          look_ahead_params=defaults, cycle_s=self._cycle_s)

    def _show_start(self, job: Job) -> None:
        """What a run or check shows at its start: counters at 0, the job's file; a
        program also starts with no messages and default high-speed settings."""
        ch = self.channel
        ch.block_count = 0
        ch.dist_prog_start_incr = 0.0
        ch.program_time_s = 0.0
        ch.file_name, ch.line, ch.file_offset, ch.block_number = job.name, 0, 0, -1
        if not job.manual:
            self._messages.clear()
            ch.messages, ch.message_count = (), 0
            ch.machining = MachiningSettings()

    def _show_decoder_state(self) -> None:
        """The #MSG texts and the #HSC/G133/.. settings the decoder reached."""
        ch = self.channel
        new = []
        while self._messages:
            new.append(self._messages.popleft())
        if new:
            ch.messages = (tuple(reversed(new)) + ch.messages)[:MESSAGES_KEPT]
            ch.message_count += len(new)
        if self._modal is not None and self._modal.settings != ch.machining:
            ch.machining = replace(self._modal.settings)

    def _axis_limits(self) -> tuple[tuple[AxisDynamics, ...], tuple[tuple[float, float], ...]]:
        """Dynamics and software limits of the channel's axes from the effective axis
        parameters (read at each start, so an update applies from the next run)."""
        params = [self._params[n] for n in self._axis_numbers]
        dynamics = tuple(
            AxisDynamics(p.vel_max_mm_s, p.acc_max_mm_s2, p.vel_jump_mm_s) for p in params
        )
        return dynamics, tuple((p.sw_limit_min_mm, p.sw_limit_max_mm) for p in params)

    def _begin_check(self, job: Job, mode: int) -> None:
        """Start the syntax check (SYNCHK) or dry run (MACHINE_LOCK) of the program."""
        ch = self.channel
        dynamics, sw_limits = self._axis_limits()
        synchk = bool(mode & ExecutionMode.SYNCHK)
        self._check = CheckRun(
            channel_id=ch.channel_id, name=job.name, text_of=self._loader, axes=self._axes,
            axis_numbers=self._axis_numbers, tools=self._tools,
            contour_lookahead=self.config.contour_lookahead,
            start_mm=tuple(a.position_mm for a in ch.axes),
            dynamics=dynamics, sw_limits_mm=sw_limits,
            settings=ch.syn_chk if synchk else None, single_step=ch.single_block,
            deterministic=self._deterministic, files=self._files,
            surroundings=self._surroundings,
            modal=self.new_modal(tuple(a.position_mm for a in ch.axes)),
            max_errors=self._check_max_errors, interrupted=self.reset_pending.is_set,
        )
        self._check_left_out = 0
        self._released = Pause.NONE
        self._executor = None
        self._pending_error = None
        self._started_at_s = self._time_s
        ch.decoder_flags = DecoderFlag.SYNTAX_CHECK if synchk else 0
        self._show_start(job)

    def _check_cycle(self, time_s: float) -> bool:
        """One GEO cycle of a syntax check or dry run: show where the decoder is."""
        ch = self.channel
        run = self._check
        run.set_single_step(ch.single_block)
        if self._deterministic and ch.state == ChannelState.ACTIVE:
            run.advance()
        p = run.progress()
        ch.file_name, ch.line, ch.file_offset = p.file, p.line, p.offset
        ch.block_number = p.block_number
        ch.block_count = p.blocks
        ch.program_time_s = time_s - self._started_at_s
        for found in p.errors:
            err = found.error
            self._raise(ChannelError(int(err.id), err.message, found.file, found.line,
                                     found.column, warning=True), to_log=False, keep_last=True)
        # errors over limits.check_max_errors are counted, not listed
        ch.error_count += p.left_out - self._check_left_out
        self._check_left_out = p.left_out
        flags = ch.decoder_flags & DecoderFlag.SYNTAX_CHECK
        if p.pause == Pause.AFTER_ERROR:
            flags |= DecoderFlag.WAIT_AFTER_ERROR
        elif p.pause != Pause.NONE:
            flags |= DecoderFlag.WAIT_CONTINUE
        if self._released == Pause.AFTER_ERROR:  # the implicit enable, cleared this cycle
            flags |= DecoderFlag.SYNTAX_CHECK_RELEASE_CLEARED
        elif self._released != Pause.NONE:
            flags |= DecoderFlag.WAIT_RELEASE_CLEARED
        self._released = Pause.NONE
        ch.decoder_flags = flags
        if p.done:
            self._check = None
            ch.decoder_flags = 0
            if p.failure is not None:
                err = p.failure.error
                self._fail(ChannelError(int(err.id), err.message, p.failure.file,
                                        p.failure.line, p.failure.column))
                return False
            if p.stopped_early:
                self._raise(ChannelError(
                    CHECK_STOPPED_WARNING, f"syntax check stopped after {p.error_count} errors "
                    "(syn_chk.errors_total, P-CHAN-00019)", p.file, p.line, warning=True))
            return self._end_program()
        if p.pause != Pause.NONE:
            ch.state = ChannelState.HOLD
            ch.waiting_for_start = True
            return False
        return ch.state == ChannelState.ACTIVE

    def _prod_time_cycle(self) -> bool:
        """PROD_TIME: simulate cycles of the run in kernel time as fast as the CPU allows
        (a share of each GEO cycle); ``program_time`` is the simulated time."""
        if self.channel.state == ChannelState.HOLD:
            return False
        deadline = time.perf_counter() + _PROD_TIME_SHARE * self._cycle_s
        for n in range(PROD_TIME_STEPS_PER_CYCLE):
            if not self._deterministic:
                if n % 4 == 0 and time.perf_counter() > deadline:
                    break
                if not self._feed_ready():  # the decoder is behind: go on next cycle
                    break
            self._sim_steps += 1
            self._time_s = self._started_at_s + self._sim_steps * self._cycle_s
            if not self._motion_cycle(self._time_s, 1.0, output=False):
                return False
            if self._executor.waiting in (Waiting.PROGRAMMED_STOP, Waiting.SINGLE_BLOCK):
                self._executor.resume()  # M0/M1: the calculation does not wait
                self.channel.waiting_for_start = False
        return True

    def _feed_ready(self) -> bool:
        """The next cycle's feed would not wait for the decoder."""
        feed = self._feed
        if (feed is None or self._fed_all or self._backlog or self._sync is not None
                or self._pending_error is not None):
            return True
        return feed.ready(self._executor.free_slots())

    def _stop_run(self) -> None:
        if self._feed is not None:
            self._feed.cancel()
            if self._modal is not None:
                self._modal = self._feed.modal
            self._feed = None

    def _raise(self, error: ChannelError, to_log: bool = True, keep_last: bool = False) -> None:
        """List ``error``; ``to_log``: also in the channel's error log file (not the
        findings of a syntax check, which may be thousands: they go to dec0<c>.sc);
        ``keep_last``: leave the last slot free (for the error or warning that ends a
        check)."""
        ch = self.channel
        if to_log:
            log.info("channel %d: %s", ch.channel_id, error)
            self._files(self.error_log_name, f"{self._time_s:.3f} s {error}\n".encode())
        ch.error_count += 1
        if len(ch.errors) < MAX_ERRORS_KEPT - keep_last:
            ch.errors = (*ch.errors, error)

    def _fail(self, error: ChannelError) -> None:
        ch = self.channel
        self._raise(error)
        self._stop_run()
        if self._contour is not None:  # nothing more of the area will be read in
            self._contour.stop()
            self._show_contour_state()
        ch.state = ChannelState.ERROR
        ch.waiting_for_start = False
        ch.program_time_s = self._time_s - self._started_at_s
        self._write_trace(f"ERROR {error.id}")

    def _feed_blocks(self) -> None:
        executor, feed = self._executor, self._feed
        if feed is None or self._fed_all or self._pending_error is not None:
            return
        free = executor.free_slots()
        if free <= 0:
            return
        # PROD_TIME waits for the decoder as the virtual clock does: a simulated cycle
        # must never pass starved (``_prod_time_cycle`` only steps when the feed is ready)
        wait = self._deterministic or self._prod_time
        pending = self._section_pending()
        if pending and not wait:  # planned already: waiting only takes the SDA's put
            free, wait = min(free, pending), True
        items, self._backlog = self._backlog or feed.take(free, wait=wait), []
        if items:
            self._show_decoder_state()
        contour = self._contour
        for k, item in enumerate(items):
            if isinstance(item, Block) and item.contour is not None and (
                    item.contour.kind in LOOP_MARKERS):
                # a real-time loop pass: for the contour log only, never a block of the path
                if contour is not None:
                    contour.mark(item.contour)
                continue
            if isinstance(item, Block) and _waits_for_standstill(item):
                # axes change hands, or the log is cleared, at standstill: flush, feed
                # the rest after it
                self._backlog = items[k + 1:]
                if self._close(item):
                    self._sync = item
                return
            if isinstance(item, Block):
                if contour is not None:
                    contour.expect(item)
                try:
                    executor.push(item)
                except PathError as exc:
                    self._stop_feeding(_path_error(exc, item))
                    return
                self._last_pushed = item
            elif isinstance(item, PathError):  # LA_ON section planning (bottleneck)
                self._stop_feeding(_path_error(item, item.block))
                return
            elif isinstance(item, NcError):
                self._stop_feeding(ChannelError(
                    int(item.id), item.message, item.file, item.line, item.column
                ))
                return
            elif isinstance(item, DecodeEnd):
                self._fed_all = True
                if self._close(None) and contour is not None:
                    if contour.end_of_data():
                        self._warn_log_full()
                    self._show_contour_state()

    def _section_pending(self) -> int:
        """Blocks of the planned LA_ON section still to come after the last one pushed:
        the path runs towards them at the section's planned speed, so they must enter
        the buffer in time (they are planned, the wait is short and bounded)."""
        last = self._last_pushed
        if last is None or last.look_ahead is None or last.look_ahead.exit_mm_s <= 0.0:
            return 0
        return last.look_ahead.blocks_after

    def _stop_feeding(self, error: ChannelError) -> None:
        """Nothing after this error enters the path; what radius compensation holds
        back is released, so the blocks before the error run to their end."""
        self._pending_error = error
        self._close(None)  # an error of a held block replaces it: it comes first

    def _close(self, block: Block | None) -> bool:
        """End of the data so far (end of program, or ``block`` waits for standstill):
        what radius compensation holds back is released. False when that fails (the
        error takes effect where the path stops)."""
        if self._contour is not None:
            self._contour.expect(None)
        try:
            self._executor.close()
        except PathError as exc:
            self._pending_error = _path_error(exc, block)
            return False
        return True

    def cycle(self, time_s: float) -> bool:
        """One GEO cycle of the channel; True while it has motion or decoding to do."""
        self._time_s = time_s
        ch = self.channel
        executor = self._executor
        if ch.state not in (ChannelState.ACTIVE, ChannelState.HOLD):
            self.touched = False
            return False
        if not self.axes_ready and self._check is None:  # suspended, or a link waits
            if self._prod_time and self._pending_start is None:
                self._sim_steps += 1  # a real run's time runs on while a link waits
            self.touched = False
            return False
        if self._pending_start is not None:
            self._begin_pending()
            executor = self._executor
            if executor is None and self._check is None:  # the start failed (jog of path)
                self.touched = True
                return False
        self.touched = True
        if self._check is not None:
            return self._check_cycle(time_s)
        if self._prod_time:
            return self._prod_time_cycle()
        return self._motion_cycle(time_s, ch.feed_override_active / 1000.0, output=True)

    def _motion_cycle(self, time_s: float, override: float, output: bool) -> bool:
        """One interpolation cycle of the path; ``output`` False: the axes stay where
        they are (PROD_TIME). True while there is motion or decoding to do."""
        ch = self.channel
        executor = self._executor
        if output and executor.single_block != ch.single_block:
            executor.single_block = ch.single_block
        if self._sync is not None and executor.idle:
            if not self._apply_sync():
                return False
            if not self.axes_ready:  # a requested axis links first
                return False
        if self._sync is None:
            self._feed_blocks()
            if self._contour_changed:  # once per cycle, not per block
                self._contour_changed = False
                self._show_contour_state()
        # the buffer is full and more blocks wait: does its end hold the speed down?
        full = not (self._buffer_warned or self._fed_all) and executor.free_slots() == 0
        step = executor.step(override)
        if full and executor.buffer_limits_speed():
            self._warn_buffer_limits()
        if output:
            for axis, pos in zip(ch.axes, step.position_mm, strict=True):
                axis.position_mm = pos
                axis.command_position_incr = round(pos * _INCR_PER_MM)
            ch.path_velocity_mm_s = step.path_velocity_mm_s
            ch.programmed_velocity_mm_s = step.programmed_velocity_mm_s
            ch.remaining_in_block_mm = step.remaining_in_block_mm
            ch.dist_prog_start_incr = step.distance_mm * _INCR_PER_MM
        ch.program_time_s = time_s - self._started_at_s
        if self._trace is not None:
            shown_line = step.current.source.line if step.current is not None else 0
            self._trace.record(ch.program_time_s, step.position_mm, step.distance_mm,
                               step.path_velocity_mm_s, step.programmed_velocity_mm_s,
                               shown_line)
        for block in step.finished:
            ch.block_count += 1
            if self._contour is not None and block.contour is not None and (
                    block.contour.kind == ContourKind.DISTANCE_CLEAR):
                self._contour.distance_cleared()  # mode 2 answers in the new distances
            if self._feed is not None and self._feed.is_marker(block):
                ch.manual_blocks_done += 1
        shown = step.current or (step.finished[-1] if step.finished else None)
        if shown is not None and not (self._feed and self._feed.is_marker(shown)):
            src = shown.source
            ch.file_name, ch.line, ch.file_offset = src.file, src.line, src.offset
            ch.block_number = shown.number if shown.number is not None else -1
        stopped = step.stopped_at
        if stopped is not None and stopped.stop == StopKind.PROGRAM_END:
            return self._end_program()
        # M0/M1 or a single-block stop: the path stands at a block end until START.
        ch.waiting_for_start = ch.state == ChannelState.ACTIVE and executor.waiting in (
            Waiting.PROGRAMMED_STOP, Waiting.SINGLE_BLOCK,
        )
        if executor.idle:
            if self._pending_error is not None:
                self._fail(self._pending_error)
                return False
            if self._fed_all:
                return self._end_program()
            if ch.mode == ChannelMode.MDI and self._feed is not None and self._feed.keep_open:
                return False  # extended MDI: waiting for the next manual block
        return True

    def _apply_sync(self) -> bool:
        """Carry out the block the path stands at (axis exchange, LOG CLEAR); False
        when the channel failed."""
        block, self._sync = self._sync, None
        ch = self.channel
        ch.block_count += 1
        src = block.source
        ch.file_name, ch.line, ch.file_offset = src.file, src.line, src.offset
        ch.block_number = block.number if block.number is not None else -1
        if self._contour is not None:
            self._contour.count_block()
        exchange: AxisExchange | None = block.axis_exchange
        if exchange is None:  # #CONTOUR LOOKAHEAD LOG CLEAR
            if self._contour is not None:
                self._contour.clear()
                self._show_contour_state()
            return True
        release = exchange.kind == AxisExchangeKind.RELEASE
        for index in exchange.axes:
            ch.axes[index].released = release
        return self._check_jog_of_path()  # P-CHAN-00306: checked at axis exchange too

    # ------------------------------------------------------------ contour look-ahead

    def _prepared(self, items: list[Segment | Block]) -> None:
        """Blocks entering the look-ahead buffer: the contour log sees them."""
        if self._contour.take(items):
            self._warn_log_full()
        self._contour_changed = True

    def _warn_buffer_limits(self) -> None:
        """Warn (once per run) that the look-ahead buffer's size limits the path speed,
        at the block the path is in."""
        self._buffer_warned = True
        ch = self.channel
        self._raise(ChannelError(
            int(PathErrorId.BUFFER_LIMITS_SPEED),
            f"the look-ahead buffer of {self._buffer_blocks} blocks limits the path speed "
            f"to {ch.path_velocity_mm_s:.1f} mm/s (the path must be able to stop after the "
            "last buffered block): choose a larger buffer (interpolator_function, "
            "P-CHAN-00650) or program LA_ON", ch.file_name, ch.line, warning=True))

    def _warn_log_full(self) -> None:
        """Warn (once per marked area) that the log dropped elements, at the block that
        did not fit."""
        block = self._contour.dropped_at
        src = block.source if block is not None else SourceRef(self.channel.file_name, 0)
        self._raise(ChannelError(
            LOG_FULL_WARNING,
            f"the contour look-ahead log is full ({self._contour.log_max} entries, "
            "contour_lookahead_log_max P-CHAN-00658): later elements of the marked area "
            "are not logged", src.file, src.line, src.column, warning=True,
        ))

    def _show_contour_state(self) -> None:
        """The unit's state after blocks were prepared, the log cleared or ended."""
        log = self._contour
        self.channel.contour = replace(
            self.channel.contour, max_dist_prog_start_incr=log.max_dist_prog_start_incr,
            count_logged_blocks=len(log.log), log_active=log.active,
        )

    def answer_contour_request(self) -> None:
        """The PLC set the semaphore: fill the response from the log (mode 1) or the
        recent elements (mode 2), then reset the semaphore."""
        unit = self.channel.contour
        response = () if self._contour is None else self._contour.answer(
            unit.request_start_position, unit.request_length)
        self.channel.contour = replace(unit, response=response, semaphor=False)

    def _end_program(self) -> bool:
        ch = self.channel
        self._stop_run()
        if self._contour is not None and not self._contour.complete:
            # M30 reached before the end of the data was taken: what a loop held back
            # is logged now
            if self._contour.end_of_data():
                self._warn_log_full()
            self._show_contour_state()
        ch.state = ChannelState.READY
        ch.waiting_for_start = False
        ch.path_velocity_mm_s = ch.remaining_in_block_mm = 0.0
        ch.program_time_s = self._time_s - self._started_at_s
        self._write_trace("READY")
        return False

    def _write_trace(self, ended: str) -> None:
        """The end of a traced PROD_TIME run: its rows go to the program store."""
        trace, self._trace = self._trace, None
        if trace is not None:
            # formatted by the store writer's thread, not in this cycle
            self._files(trace_file_name(self.channel.channel_id),
                        partial(trace.csv_bytes, ended), replace=True)


def _path_error(exc: PathError, block: Block | None) -> ChannelError:
    """The channel error of a path error, at the block it names (else ``block``)."""
    named = exc.block if exc.block is not None else block
    if named is None:
        return ChannelError(int(exc.id), exc.message)
    src = named.source
    return ChannelError(int(exc.id), exc.message, src.file, src.line, src.column)


def _waits_for_standstill(block: Block) -> bool:
    """An axis exchange or a LOG CLEAR: the path stops, the block runs at standstill."""
    if block.axis_exchange is not None:
        return True
    return block.contour is not None and block.contour.kind == ContourKind.LOG_CLEAR
