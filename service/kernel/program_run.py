"""One run of a program (or of manual blocks) in a channel: what it owns and its cycle.

A ``ProgramRun`` is created when the run begins (START, a manual block, once the axes
are linked) and dropped when it ends, fails or is RESET; everything that belongs to one
run lives here, so nothing has to be reset by hand. Its decoder runs in the run's SDA
thread (``DecoderFeed``); blocks enter the look-ahead buffer of the ``PathExecutor`` as
slots free up, and each GEO cycle steps the path once (``cycle``).

``ProdTimeRun`` is the production-time simulation (PROD_TIME): the same run, but the
axes stay where they are and each GEO cycle simulates as many cycles of the path as the
CPU allows. The syntax check and dry run are the third kind (``channel_check``).

A run never changes the channel's state: ``cycle`` answers a ``Step`` and the
``ChannelRunner`` makes the transition (end of program, error, pause).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import replace
from enum import IntEnum
from functools import partial
from typing import Protocol

from cnc_objects.protocol.units import UM01_PER_MM
from cnc_objects.protocol.values import ExecutionMode

from .alarms import AlarmClass
from .channel_mode import ChannelMode, ChannelState
from .channel_parts import BlockShown, PathShown
from .contour_lookahead import LOG_FULL_WARNING, ContourLog
from .decoder_feed import DecodeEnd, DecoderFeed, Item, Job
from .nc import ModalState, NcError
from .nc.blocks import (
    AxisExchange,
    AxisExchangeKind,
    Block,
    ContourKind,
    ManualModeRequest,
    SourceRef,
    StopKind,
    TrafoUse,
)
from .nc.contour import LOOP_MARKERS
from .nc.tool_data import ZeroOffsetWrite
from .operator_switches import with_optional_stop
from .path.errors import PathErrorId
from .path.executor import PathError, PathExecutor
from .path.interpolator import StepResult, Waiting
from .path.segments import Segment
from .path_kinematics import PathKinematics
from .plc_functions import PlcFunctions
from .prod_time_trace import ProdTimeTrace, trace_file_name
from .state import BLOCK_START_COLUMN, Channel, ContourLookaheadUnit, ErrorEntry
from .tool_life import count_cutting
from .tooling import show_block_tooling
from .tooling_view import ChannelTooling
from .wait_reason import WaitReason, manual_open, path_wait_reason

_NOT_WAITING, _OVERRIDE_ZERO = int(WaitReason.NONE), int(WaitReason.OVERRIDE_ZERO)
# an int, not the flag: ``int & IntFlag`` goes through enum's Python-level __rand__,
# about 2 us, asked in every cycle (issue 37, short blocks)
_SUPPRESS_TECHNO = int(ExecutionMode.SUPPRESS_TECHNO_OUTPUT)
PROD_TIME_STEPS_PER_CYCLE = 5_000  # virtual clock: simulated cycles per GEO cycle (PROD_TIME)
_PROD_TIME_SHARE = 0.4  # realtime clock: share of a GEO cycle the calculation may use


class Step(IntEnum):
    """What one GEO cycle of a run came to."""

    BUSY = 1  # motion or decoding to do
    WAITING = 2  # nothing to do this cycle (a link, the next manual block, HOLD)
    ENDED = 3  # the end of the program: the channel becomes READY
    FAILED = 4  # an error stopped the run (``failure``): the channel goes to ERROR
    PAUSED = 5  # the syntax check waits for START: the channel goes to HOLD


class RunHost(Protocol):
    """What a run needs of its channel runner."""

    time_s: float  # kernel time of the cycle (PROD_TIME: the simulated time)
    plc: PlcFunctions  # the channel's M/S/T output to the PLC and its spindle

    @property
    def axes_ready(self) -> bool:
        """The channel's output is not suspended and every axis in it is linked."""

    def list_error(self, error: ErrorEntry, to_log: bool = True,
                   keep_last: bool = False, alarm_class: AlarmClass | None = None) -> None:
        """Put ``error`` (a warning here) in the channel's error list and raise it as an
        alarm (of ``alarm_class`` when not the one of its id)."""

    def show_decoder_state(self) -> None:
        """Show the #MSG texts and machining settings the decoder reached."""

    def jog_of_path_error(self) -> ErrorEntry | None:
        """The error that keeps a jog-of-path channel from working (None: it may)."""

    def referenced(self, axes: tuple[int, ...]) -> None:
        """G74 homed the channel axes with these indices."""

    def locked_axes(self) -> frozenset[int]:
        """Axes a program block must not move: they need homing (P-AXIS-00277) and
        are not referenced."""

    @property
    def manual_offsets_mm(self) -> tuple[float, ...] | None:
        """The G200/G201 manual offsets to add to the path's output (None: all 0)."""

    def manual_mode(self, request: ManualModeRequest) -> None:
        """The path reached a G200/G201/G202 block."""

    def zero_offsets_written(self, writes: tuple[ZeroOffsetWrite, ...]) -> None:
        """The path reached the block after the program's ``V.G.NP`` writes."""


class ChannelRun(Protocol):
    """What every kind of run offers the channel runner."""

    started_at_s: float  # kernel time the run began (program time counts from it)
    failure: ErrorEntry | None  # the error of a FAILED step

    @property
    def ignores_feedhold(self) -> bool:
        """A dry run goes on through feedhold."""

    def cycle(self, time_s: float) -> Step:
        """One GEO cycle of the run."""

    def hold(self) -> None:
        """Feedhold (the channel is HOLD from now on)."""

    def resume(self) -> None:
        """START in HOLD, or after a programmed or single-block stop."""

    def cancel(self) -> ModalState | None:
        """End the run at once (RESET, end, error); the modal state it reached."""

    def wait_reason(self) -> int:
        """Why the run stands after this cycle, a ``WaitReason``
        (``wait_reason.path_wait_reason``)."""


class ProgramRun:
    """A real run: blocks from the decoder move the channel's axes along the path."""

    _waits_for_decoder = False  # PROD_TIME: every take waits for the decoder
    _skips_cycles = True  # cruising cycles may be run in bulk (not PROD_TIME: traced)
    _writes_tables = True  # the program's V.G.NP writes reach the live table (not PROD_TIME)

    def __init__(self, host: RunHost, channel: Channel, feed: DecoderFeed,
                 executor: PathExecutor, contour: ContourLog | None, *,
                 started_at_s: float, buffer_blocks: int, deterministic: bool,
                 kinematics: PathKinematics | None = None,
                 trafo: TrafoUse | None = None) -> None:
        """``contour``: the contour look-ahead log of this run (None: not configured);
        ``kinematics``: the channel's (None: none); ``trafo``: #TRAFO ON is in effect
        from the start (the executor's position is then in programmed coordinates)."""
        self._host = host
        self._kinematics = kinematics
        self._trafo = trafo  # #TRAFO ON: the path's positions are tip and orientation
        self.channel = channel
        self.feed = feed
        self.executor = executor
        self.contour = contour
        self.started_at_s = started_at_s
        self._buffer_blocks = buffer_blocks
        self._deterministic = deterministic  # virtual clock: wait for the decoder
        # a block that waits for standstill (axis exchange, LOG CLEAR: flush and wait)
        self._sync: Block | None = None
        self._backlog: list[Item] = []  # decoded items that came after it
        self._contour_changed = False  # blocks were prepared: show the unit's new state
        self._last_pushed: Block | None = None  # the block that entered the buffer last
        self._buffer_warned = False  # BUFFER_LIMITS_SPEED shown in this run
        self._pending_error: ErrorEntry | None = None  # takes effect where the path stops
        # axes that need homing and are not referenced (P-AXIS-00277), less those a G74
        # block fed in this run homes: the blocks after it find them referenced
        self._locked = host.locked_axes()
        self._fed_all = False
        # manual blocks of a plain MDI run finished but not shown yet: they are counted
        # with the run's end, so that a client that waits on the count finds the channel
        # ready for the next manual block (the decoder's end may come cycles later)
        self._manual_done_at_end = 0
        self._technology_part: Block | None = None  # the last pre/post block finished
        self._tooling_shown: object | None = None  # the Block.tooling shown last
        self.failure: ErrorEntry | None = None
        if contour is not None:
            executor.on_prepared = self._prepared

    # ------------------------------------------------------------ commands

    @property
    def ignores_feedhold(self) -> bool:
        """Feedhold stops the path."""
        return False

    def add(self, job: Job) -> None:
        """Extended MDI: a further manual block continues the same program."""
        self.feed.add(job)

    def hold(self) -> None:
        """Feedhold: decelerate on the path."""
        self.executor.hold()

    def resume(self) -> None:
        """Go on from HOLD or a stop at a block end."""
        self.executor.resume()

    def cancel(self) -> ModalState | None:
        """Stop decoding and the path at once; the modal state the decoder reached."""
        self.feed.cancel()
        self.executor.stop_now()
        return self.feed.modal

    def wait_reason(self) -> int:
        """What the path waits for after this cycle (a ``WaitReason``): a stop, dwell or
        acknowledge at a block end, override 0, or blocks from the decoder (or the
        operator, in extended MDI)."""
        executor, ch = self.executor, self.channel
        override = (ch.switches.rapid_override_per_mille if executor.in_rapid  # G0: rapid override
                    else ch.switches.feed_override_per_mille)
        if executor.running:  # the common case, kept short
            return _NOT_WAITING if override else _OVERRIDE_ZERO
        waiting = executor.waiting
        more = not (self._fed_all or self._pending_error is not None or self._sync is not None)
        return path_wait_reason(
            waiting, executor.waiting_at, self._technology(),
            has_motion=executor.has_motion, override_per_mille=override,
            more_blocks=more, manual_open=manual_open(ch, self.feed.keep_open))

    # ------------------------------------------------------------ cycle

    def cycle(self, time_s: float) -> Step:
        """One interpolation cycle of the path, output to the channel's axes."""
        return self._motion_cycle(time_s, self.channel.switches.feed_override_per_mille / 1000.0,
                                  output=True)

    def _motion_cycle(self, time_s: float, override: float, output: bool) -> Step:
        """One interpolation cycle of the path; ``output`` False: the axes stay where
        they are (PROD_TIME)."""
        ch = self.channel
        executor = self.executor
        if output and executor.single_block != ch.switches.single_block:
            executor.single_block = ch.switches.single_block
        if self._sync is not None and executor.idle:
            failure = self._apply_sync()
            if failure is not None:
                return self._fail(failure)
            if not self._host.axes_ready:  # a requested axis links first
                return Step.WAITING
        plc = self._technology()
        if (plc is not None and executor.waiting == Waiting.TECHNOLOGY
                and plc.all_acknowledged()):
            executor.release_technology()  # acknowledged in the last cycle: go on
        if plc is not None:
            for post in plc.stops_to_release():  # MVS_SNS acknowledged before its end
                executor.release_stop(post)
        if self._sync is None:
            self._feed_blocks()
            if self._contour_changed:  # once per cycle, not per block
                self._contour_changed = False
                self._show_contour_state()
        # the buffer is full and more blocks wait: does its end hold the speed down?
        full = not (self._buffer_warned or self._fed_all) and executor.free_slots() == 0
        executor.set_rapid_override(ch.switches.rapid_override_per_mille / 1000.0)
        step = executor.step(override)
        if full and executor.buffer_limits_speed():
            self._warn_buffer_limits()
        self._show_cycles(step, time_s, 1, output)
        self._stepped(step)
        self._show_tooling(step)
        counted = manual_done = 0
        for block in step.finished:
            if plc is not None and plc.block_finished(block, time_s):
                self._technology_part = block
                continue  # a pre/post block of the technology output, not counted
            counted += 1
            if block.homing_axes and output:  # G74 done: the axes are referenced
                self._host.referenced(block.homing_axes)
            if block.manual_mode is not None and output:  # G200 / G201 / G202
                self._host.manual_mode(block.manual_mode)
            if self.contour is not None and block.contour is not None and (
                    block.contour.kind == ContourKind.DISTANCE_CLEAR):
                self.contour.distance_cleared()  # mode 2 answers in the new distances
            if self.feed.is_marker(block):
                manual_done += 1
        if manual_done and not self.feed.keep_open:
            self._manual_done_at_end += manual_done
            manual_done = 0
        shown = step.current or (step.finished[-1] if step.finished else None)
        if shown is not None and not self.feed.is_marker(shown):
            src = shown.source
            number = shown.number if shown.number is not None else -1
            was = ch.block
            if (counted or manual_done or src.line != was.line or src.file != was.file_name
                    or number != was.block_number):
                ch.block = BlockShown(
                    file_name=src.file, line=src.line, file_offset=src.offset,
                    block_number=number, block_count=was.block_count + counted,
                    manual_blocks_done=was.manual_blocks_done + manual_done)
        elif counted or manual_done:
            ch.block = ch.block._replace(
                block_count=ch.block.block_count + counted,
                manual_blocks_done=ch.block.manual_blocks_done + manual_done)
        if (executor.waiting == Waiting.SINGLE_BLOCK and step.current is not None
                and step.current is self._technology_part):
            executor.resume()  # not a block of the program: single block goes on
        stopped = step.stopped_at
        if stopped is not None and stopped.stop == StopKind.PROGRAM_END:
            return self._ended()
        # M0/M1 or a single-block stop: the path stands at a block end until START.
        waiting_for_start = ch.state == ChannelState.ACTIVE and executor.waiting in (
            Waiting.PROGRAMMED_STOP, Waiting.SINGLE_BLOCK,
        )
        if waiting_for_start != ch.program.waiting_for_start:
            ch.program = replace(ch.program, waiting_for_start=waiting_for_start)
        if executor.idle:
            if self._pending_error is not None:
                return self._fail(self._pending_error)
            if self._fed_all:
                return self._ended()
            if ch.mode == ChannelMode.MDI and self.feed.keep_open:
                return Step.WAITING  # extended MDI: waiting for the next manual block
        return Step.BUSY

    def _ended(self) -> Step:
        """The run has ended: the manual blocks it held back are counted now, in the
        same cycle as the channel's return to READY."""
        if self._manual_done_at_end:
            block = self.channel.block
            self.channel.block = block._replace(
                manual_blocks_done=block.manual_blocks_done + self._manual_done_at_end)
            self._manual_done_at_end = 0
        return Step.ENDED

    def _show_cycles(self, step: StepResult, time_s: float, cycles: int, output: bool) -> None:
        """What every cycle shows, stepped or the last of a bulk (``cruise``): the path's
        values and the axes (``output`` False: they stay, PROD_TIME), the tool life of
        ``cycles`` cycles (a dry run cuts nothing), the program time at ``time_s``."""
        program_time_s = time_s - self.started_at_s
        if output:
            self._output(step, program_time_s)
            count_cutting(self.channel, step.current, cycles)
        else:
            self.channel.path = self.channel.path._replace(program_time_s=program_time_s)

    def _output(self, step: StepResult, program_time_s: float) -> None:
        """The cycle's path values shown in the channel (``program_time_s``: since the
        start), its axes' command positions."""
        ch = self.channel
        offsets = self._host.manual_offsets_mm  # G200/G201 (None: no offset)
        positions = step.position_mm
        if self._trafo is not None and self._kinematics is not None:
            current = step.current
            trafo = current.trafo if current is not None and current.trafo else self._trafo
            positions = self._kinematics.axes_of(positions, trafo.tool_length_mm)
        if offsets is not None:
            positions = tuple(p + o for p, o in zip(positions, offsets, strict=True))
        for axis, pos in zip(ch.axes, positions, strict=True):
            axis.position_mm = pos
            axis.command_position_01um = round(pos * UM01_PER_MM)
        motion = step.current.motion if step.current is not None else None
        ends = () if motion is None else motion.end_mm
        for k, axis in enumerate(ch.axes):  # distance to go: to the block's end point
            axis.distance_to_go_01um = round(
                (ends[k] - step.position_mm[k]) * UM01_PER_MM) if k < len(ends) else 0
        ch.path = PathShown(
            path_velocity_mm_s=step.path_velocity_mm_s,
            programmed_velocity_mm_s=step.programmed_velocity_mm_s,
            remaining_in_block_mm=step.remaining_in_block_mm,
            dist_prog_start_01um=step.distance_mm * UM01_PER_MM,
            program_time_s=program_time_s)

    def cruise_budget(self, most: int) -> int:
        """How many of the next cycles (at most ``most``) would do nothing but move
        inside the current segment: no block to feed (the buffer is full or the program
        read to its end), nothing waited for, no re-planning, single block and override
        as the path has them. The gate of every cycle (``Kernel._cruise_budget``): a
        cycle it allows runs as ``cruise(1)``, more as a bulk; else ``cycle`` runs."""
        ch, executor = self.channel, self.executor
        if (not self._skips_cycles or self._sync is not None or self._contour_changed
                or self._pending_error is not None or executor.single_block != ch.switches.single_block
                or executor.rapid_override != ch.switches.rapid_override_per_mille / 1000.0
                or not (self._fed_all or executor.free_slots() == 0)):
            return 0
        # as ``_motion_cycle``: with the buffer full, a cycle that leaves the path held
        # down by the buffer's end shows a warning (once), so it is a cycle of its own
        full = not (self._buffer_warned or self._fed_all)
        return executor.cruise_budget(ch.switches.feed_override_per_mille / 1000.0, most, full)

    def cruise(self, cycles: int, time_s: float) -> None:
        """Run ``cycles`` cycles that ``cruise_budget`` allowed at once, the last at
        kernel time ``time_s``: the channel shows what stepping them one by one shows."""
        self._show_cycles(self.executor.cruise(cycles), time_s, cycles, True)

    def _technology(self) -> PlcFunctions | None:
        """The channel's technology output, None while it is suppressed (PROD_TIME)."""
        if self.channel.program.execution_mode_active & _SUPPRESS_TECHNO:
            return None
        return self._host.plc

    def _show_tooling(self, step: StepResult) -> None:
        """T, D, the zero offset and the PCS shift of the block being interpolated (the
        last one carrying a view, ``Block.tooling``), with the live tables (issue 39).
        A cycle without such a block costs two attribute looks."""
        view = None
        for block in step.finished:
            if block.tooling is not None:
                view = block.tooling
        current = step.current
        if current is not None and current.tooling is not None:
            view = current.tooling
        if view is None or view is self._tooling_shown:
            return
        self._tooling_shown = view
        assert isinstance(view, ChannelTooling)
        if view.nc_zero_offsets and self._writes_tables:
            self._host.zero_offsets_written(view.nc_zero_offsets)
        show_block_tooling(self.channel, view)

    def _stepped(self, step: StepResult) -> None:
        """After each interpolation cycle (a traced PROD_TIME run records it)."""

    def _fail(self, error: ErrorEntry) -> Step:
        self.failure = error
        return Step.FAILED

    def _apply_sync(self) -> ErrorEntry | None:
        """Carry out the block the path stands at (axis exchange, LOG CLEAR); the error
        when the channel cannot work after it (jog of path)."""
        block, self._sync = self._sync, None
        assert block is not None
        ch = self.channel
        src = block.source
        ch.block = ch.block._replace(
            file_name=src.file, line=src.line, file_offset=src.offset,
            block_number=block.number if block.number is not None else -1,
            block_count=ch.block.block_count + 1)
        if self.contour is not None:
            self.contour.count_block()
        if block.trafo_switch:
            self._switch_trafo(block.trafo)
            return None
        exchange: AxisExchange | None = block.axis_exchange
        if exchange is None:  # #CONTOUR LOOKAHEAD LOG CLEAR
            if self.contour is not None:
                self.contour.clear()
                self._show_contour_state()
            return None
        release = exchange.kind == AxisExchangeKind.RELEASE
        for index in exchange.axes:
            ch.axes[index].released = release
        return self._host.jog_of_path_error()  # P-CHAN-00306: checked at axis exchange too

    # ------------------------------------------------------------ feeding the path

    def _feed_blocks(self) -> None:
        executor, feed = self.executor, self.feed
        if self._fed_all or self._pending_error is not None:
            return
        free = executor.free_slots()
        if free <= 0:
            return
        # PROD_TIME waits for the decoder as the virtual clock does: a simulated cycle
        # must never pass starved (``ProdTimeRun.cycle`` only steps when the feed is ready)
        wait = self._deterministic or self._waits_for_decoder
        pending = self._section_pending()
        if pending and not wait:  # planned already: waiting only takes the SDA's put
            free, wait = min(free, pending), True
        items, self._backlog = self._backlog or feed.take(free, wait=wait), []
        if items:
            self._host.show_decoder_state()
        contour, channel = self.contour, self.channel
        plc = self._technology()  # (looked up once per cycle, not per block: issue 37)
        for k, item in enumerate(items):
            if isinstance(item, Block):
                marks = item.contour
                if marks is not None and marks.kind in LOOP_MARKERS:
                    # a real-time loop pass: for the contour log only, never a block of
                    # the path
                    if contour is not None:
                        contour.mark(marks)
                    continue
                if _waits_for_standstill(item):
                    # axes change hands, or the log is cleared, at standstill: flush,
                    # feed the rest after it
                    self._backlog = items[k + 1:]
                    if self._close(item):
                        self._sync = item
                    return
                if self._locked and _moves_locked(item, self._locked):
                    self._stop_feeding(_not_referenced(item, self._locked, channel))
                    return
                if item.homing_axes:
                    self._locked = self._locked - frozenset(item.homing_axes)
                if item.trafo is not None and self._kinematics is not None:
                    prepared = self._kinematics.prepared(item)
                    if isinstance(prepared, tuple):  # beyond a software limit
                        src = item.source
                        self._stop_feeding(ErrorEntry(prepared[0], prepared[1], src.file,
                                                      src.line, src.column))
                        return
                    item = prepared
                item = with_optional_stop(item, channel)  # M1 and its switch
                if contour is not None:
                    contour.expect(item)
                try:
                    for part in ([item] if plc is None else plc.split(item)):
                        executor.push(part)
                except PathError as exc:
                    self._stop_feeding(_path_error(exc, item))
                    return
                self._last_pushed = item
            elif isinstance(item, PathError):  # LA_ON section planning (bottleneck)
                self._stop_feeding(_path_error(item, item.block))
                return
            elif isinstance(item, NcError):
                self._stop_feeding(ErrorEntry(
                    int(item.id), item.message, item.file, item.line, item.column
                ))
                return
            elif isinstance(item, DecodeEnd):
                self._fed_all = True
                if self._close(None) and contour is not None:
                    if contour.end_of_data():
                        self._warn_log_full()
                    self._show_contour_state()

    def _switch_trafo(self, trafo: TrafoUse | None) -> None:
        """#TRAFO ON/OFF at standstill: the path's position in the other coordinates."""
        kinematics, executor = self._kinematics, self.executor
        assert kinematics is not None  # the decoder switches only with kinematics
        if trafo is not None:
            position = kinematics.program_of(executor.position_mm, trafo.tool_length_mm)
            executor.relocate(position, None)  # the limits hold for the axes: checked here
        else:
            assert self._trafo is not None
            position = kinematics.axes_of(executor.position_mm, self._trafo.tool_length_mm)
            executor.relocate(position, kinematics.sw_limits_mm)
        self._trafo = trafo

    def _section_pending(self) -> int:
        """Blocks of the planned LA_ON section still to come after the last one pushed:
        the path runs towards them at the section's planned speed, so they must enter
        the buffer in time (they are planned, the wait is short and bounded)."""
        last = self._last_pushed
        if last is None or last.look_ahead is None or last.look_ahead.exit_mm_s <= 0.0:
            return 0
        return last.look_ahead.blocks_after

    def _stop_feeding(self, error: ErrorEntry) -> None:
        """Nothing after this error enters the path; what radius compensation holds
        back is released, so the blocks before the error run to their end."""
        self._pending_error = error
        self._close(None)  # an error of a held block replaces it: it comes first

    def _close(self, block: Block | None) -> bool:
        """End of the data so far (end of program, or ``block`` waits for standstill):
        what radius compensation holds back is released. False when that fails (the
        error takes effect where the path stops)."""
        if self.contour is not None:
            self.contour.expect(None)
        try:
            self.executor.close()
        except PathError as exc:
            self._pending_error = _path_error(exc, block)
            return False
        return True

    def _feed_ready(self) -> bool:
        """The next cycle's feed would not wait for the decoder."""
        if (self._fed_all or self._backlog or self._sync is not None
                or self._pending_error is not None):
            return True
        return self.feed.ready(self.executor.free_slots())

    # ------------------------------------------------------------ contour look-ahead

    def _prepared(self, items: list[Segment | Block]) -> None:
        """Blocks entering the look-ahead buffer: the contour log sees them."""
        assert self.contour is not None
        if self.contour.take(items):
            self._warn_log_full()
        self._contour_changed = True

    def _warn_buffer_limits(self) -> None:
        """Warn (once per run) that the look-ahead buffer's size limits the path speed,
        at the block the path is in."""
        self._buffer_warned = True
        ch = self.channel
        self._host.list_error(ErrorEntry(
            int(PathErrorId.BUFFER_LIMITS_SPEED),
            f"the look-ahead buffer of {self._buffer_blocks} blocks limits the path speed "
            f"to {ch.path.path_velocity_mm_s:.1f} mm/s (the path must be able to stop after the "
            "last buffered block): choose a larger buffer (interpolator_function, "
            "P-CHAN-00650) or program LA_ON", ch.block.file_name, ch.block.line, BLOCK_START_COLUMN,
            warning=True))

    def _warn_log_full(self) -> None:
        assert self.contour is not None
        self._host.list_error(log_full_warning(self.contour, self.channel.block.file_name))

    def _show_contour_state(self) -> None:
        assert self.contour is not None
        show_contour_state(self.channel, self.contour)


class ProdTimeRun(ProgramRun):
    """PROD_TIME: the run is simulated in kernel time as fast as the CPU allows (a share
    of each GEO cycle); no axis moves, ``program_time`` is the simulated time. With
    ``trace`` every simulated cycle is recorded (``ch<c>.prod_time_trace``)."""

    _waits_for_decoder = True
    _skips_cycles = False  # each GEO cycle simulates many cycles itself
    _writes_tables = False  # a simulation: the tables stay as they are

    def __init__(self, host: RunHost, channel: Channel, feed: DecoderFeed,
                 executor: PathExecutor, contour: ContourLog | None, *,
                 started_at_s: float, buffer_blocks: int, deterministic: bool,
                 cycle_s: float, trace: ProdTimeTrace | None,
                 kinematics: PathKinematics | None = None,
                 trafo: TrafoUse | None = None) -> None:
        super().__init__(host, channel, feed, executor, contour, started_at_s=started_at_s,
                         buffer_blocks=buffer_blocks, deterministic=deterministic,
                         kinematics=kinematics, trafo=trafo)
        self._cycle_s = cycle_s
        self.sim_steps = 0  # cycles simulated so far
        self.trace = trace

    def hold(self) -> None:
        """Feedhold pauses the calculation (``cycle`` does nothing in HOLD)."""

    def _technology(self) -> PlcFunctions | None:
        """The calculation outputs no technology and waits for no acknowledge."""
        return None

    def wait_for_link(self) -> None:
        """A GEO cycle passed while a link waits: a real run's time runs on."""
        self.sim_steps += 1

    def cycle(self, time_s: float) -> Step:
        """Simulate cycles of the run until the share of this GEO cycle is used."""
        if self.channel.state == ChannelState.HOLD:
            return Step.WAITING
        deadline = time.perf_counter() + _PROD_TIME_SHARE * self._cycle_s
        for n in range(PROD_TIME_STEPS_PER_CYCLE):
            if not self._deterministic:
                if n % 4 == 0 and time.perf_counter() > deadline:
                    break
                if not self._feed_ready():  # the decoder is behind: go on next cycle
                    break
            self.sim_steps += 1
            self._host.time_s = self.started_at_s + self.sim_steps * self._cycle_s
            step = self._motion_cycle(self._host.time_s, 1.0, output=False)
            if step != Step.BUSY:
                return step
            if self.executor.waiting in (Waiting.PROGRAMMED_STOP, Waiting.SINGLE_BLOCK):
                self.executor.resume()  # M0/M1: the calculation does not wait
                self.channel.program = replace(self.channel.program, waiting_for_start=False)
        return Step.BUSY

    def _stepped(self, step: StepResult) -> None:
        if self.trace is not None:
            ch = self.channel
            shown_line = step.current.source.line if step.current is not None else 0
            self.trace.record(ch.path.program_time_s, step.position_mm, step.distance_mm,
                              step.path_velocity_mm_s, step.programmed_velocity_mm_s,
                              shown_line)

    def write_trace(self, ended: str, files: Callable[..., None]) -> None:
        """The end of a traced run: its rows go to the output area."""
        trace, self.trace = self.trace, None
        if trace is not None:
            # formatted by the output writer's thread, not in this cycle
            files(trace_file_name(self.channel.channel_id),
                  partial(trace.csv_bytes, ended), replace=True)


def show_contour_state(channel: Channel, contour: ContourLog) -> None:
    """The contour look-ahead unit's state after blocks were prepared, the log cleared
    or ended."""
    unit = channel.contour
    # built field by field (a new field of the unit must be added here): ``replace``
    # looks the fields up at each call, and this runs in every cycle that prepared
    # blocks (issue 37)
    channel.contour = ContourLookaheadUnit(
        request_start_position=unit.request_start_position,
        request_length=unit.request_length, semaphor=unit.semaphor,
        max_dist_prog_start_01um=contour.max_dist_prog_start_01um,
        count_logged_blocks=len(contour.log), log_active=contour.active,
        response=unit.response,
    )


def log_full_warning(contour: ContourLog, file_name: str) -> ErrorEntry:
    """The warning (once per marked area) that the log dropped elements, at the block
    that did not fit (else in ``file_name``)."""
    block = contour.dropped_at
    src = block.source if block is not None else SourceRef(file_name, 0)
    return ErrorEntry(
        LOG_FULL_WARNING,
        f"the contour look-ahead log is full ({contour.log_max} entries, "
        "contour_lookahead_log_max P-CHAN-00658): later elements of the marked area "
        "are not logged", src.file, src.line, src.column, warning=True,
    )


def _path_error(exc: PathError, block: Block | None) -> ErrorEntry:
    """The channel error of a path error, at the block it names (else ``block``)."""
    named = exc.block if exc.block is not None else block
    if named is None:
        return ErrorEntry(int(exc.id), exc.message)
    src = named.source
    return ErrorEntry(int(exc.id), exc.message, src.file, src.line, src.column)


def _moves_locked(block: Block, locked: frozenset[int]) -> bool:
    """The block moves one of the ``locked`` axes (a G74 block moves its own axes to
    home them: that is allowed)."""
    motion = block.motion
    if motion is None:
        return False
    homing = block.homing_axes
    return any(motion.start_mm[k] != motion.end_mm[k] for k in locked if k not in homing)


def _not_referenced(block: Block, locked: frozenset[int], channel: Channel) -> ErrorEntry:
    """Error 50110 at ``block``: it would move an axis that must be homed first."""
    motion = block.motion
    assert motion is not None
    names = ", ".join(channel.axes[k].name for k in sorted(locked)
                      if motion.start_mm[k] != motion.end_mm[k])
    src = block.source
    return ErrorEntry(int(PathErrorId.AXIS_NOT_REFERENCED),
                      f"axis {names} is not referenced and must be homed before a program "
                      "moves it (P-AXIS-00277 prog_move_requires_homing): G74 first",
                      src.file, src.line, src.column)


def _waits_for_standstill(block: Block) -> bool:
    """An axis exchange, a LOG CLEAR or #TRAFO ON/OFF: the path stops, the block runs
    at standstill."""
    if block.axis_exchange is not None or block.trafo_switch:
        return True
    return block.contour is not None and block.contour.kind == ContourKind.LOG_CLEAR
