"""The kernel: its state and the GEO cycle task in a thread of its own.

Every cycle: apply the queued commands (in arrival order), run the cycle's work, update
the statistics, publish a snapshot, call the ``on_cycle_end`` hook. The service talks to
the kernel only through ``submit`` (commands in) and ``snapshot`` (state out); nothing
here knows about sockets, frames or addresses. A reader that must see one cycle across
many reads (a notification pass: each sample's data and timestamp from the same cycle)
pins the snapshot on its thread with ``reading``.
"""

from __future__ import annotations

import logging
import queue
import threading
import time
from collections import deque
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from enum import Enum

from ..machine_config import MachineConfig
from .alarms import KERNEL_FAULT_ID, AlarmClass, AlarmLog
from .axis_params import AxisParameters, initialise_axes
from .channel_run import ChannelRunner
from .clock import Clock, LatenessHistogram, VirtualClock
from .commands import Command, Refusal, RefusalReason, ResetChannel
from .kernel_state import KernelState
from .nc.source import NcText
from .nc.tool_data import ToolingTables
from .realtime_priority import RealtimeGrant, worker_priority
from .runner_services import RunnerServices
from .state import CycleStats, ErrorEntry, Snapshot
from .step_clock import NOT_STEPPING, STEP_RUNNING, StepClock, StepCycles
from .switchover import Switchover
from .syntax_check import CHECK_MAX_ERRORS
from .workers import Workers

log = logging.getLogger(__name__)

Done = Callable[[Refusal | None], None]
Loader = Callable[[str], NcText]  # a program's text, or its file read as a stream


#: The most cycles the event-speed virtual clock runs in one bulk step: the queue is
#: looked at between two (a command waits at most a few ms of wall time).
BULK_CYCLES_MAX = 10_000


def _no_programs(name: str) -> str:
    raise KeyError(name)


class Control(Enum):
    """Run control of the whole kernel (ADS WriteControl)."""

    RUN = "run"  # cycles run
    STOP = "stop"  # cycles pause; reads serve the last snapshot, writes are refused
    RESET = "reset"  # state re-initialised from the configuration, then RUN


@dataclass(frozen=True, slots=True)
class ControlCommand:
    """A run-control request, applied by the cycle thread like any command."""

    control: Control


@dataclass(frozen=True, slots=True)
class ResetCycleStats:
    """``cnc_cycle_stats_reset_w``: TRUE forgets the cycle task's figures (overruns,
    lateness, longest execution), so that a measurement starts there; FALSE does nothing
    (a PLC may write the bit back). Applied by the cycle thread like any command."""

    value: bool


class _Shutdown:
    """The queue entry that stops the cycle thread (``Kernel.close``)."""


_SHUTDOWN = _Shutdown()


class _Pin(threading.local):
    """The snapshot one thread has pinned (``Kernel.reading``); None: it reads the newest."""

    snapshot: Snapshot | None = None


class _Reading:
    """``Kernel.reading``'s block (a class, not a generator: a notification pass pins
    once per due cycle, issue 37)."""

    __slots__ = ("_kernel", "_snapshot", "_owner")

    def __init__(self, kernel: Kernel, snapshot: Snapshot | None) -> None:
        self._kernel, self._snapshot, self._owner = kernel, snapshot, False

    def __enter__(self) -> Snapshot:
        pin = self._kernel._pin
        held = pin.snapshot
        if held is not None:
            return held  # nested: the outer pin holds
        snapshot = self._snapshot
        pinned = pin.snapshot = self._kernel._latest if snapshot is None else snapshot
        self._owner = True
        return pinned

    def __exit__(self, *exc: object) -> None:
        if self._owner:
            self._kernel._pin.snapshot = None


def _no_answer(_result: Refusal | None) -> None:
    """The ``done`` of the shutdown entry: nobody waits for it."""


#: what the kernel's queue takes from the service
KernelCommand = Command | ControlCommand | ResetCycleStats | StepCycles
#: a queued command and the callback that gets its answer
Queued = tuple[KernelCommand | _Shutdown, Done]


class Kernel:
    """Kernel state plus the cycle thread that owns it."""

    def __init__(
        self,
        config: MachineConfig,
        clock: Clock,
        loader: Loader = _no_programs,
        exists: Callable[[str], bool] = lambda name: False,
        files: Callable[..., None] = lambda name, data, replace=False: None,
        save: Callable[[str, bytes, bool], None] = lambda name, data, replace: None,
        check_max_errors: int = CHECK_MAX_ERRORS,
        alarms: AlarmLog | None = None,
        tables: Sequence[ToolingTables | None] = (),
        idle_steps_max: int | None = None,
        rest_when_idle: bool = True,
        repeatable: bool = False,
    ) -> None:
        """``loader(name)`` returns a program's text (KeyError when absent) and
        ``exists(name)`` says whether it is there: the program store, seen by the kernel,
        which never writes there. The files it writes go to the output area:
        ``files(name, data, replace=False)`` for its own (a log line at the end, or a
        report as the whole content), ``save(name, data, replace)`` for those an NC
        program writes (``#MSG SAVE``, a cycle's result), which may raise
        ``nc.technology.OutputLimitReached``; neither blocks. ``check_max_errors``:
        errors one syntax check keeps ([limits] check_max_errors). ``alarms``: the log
        every channel raises its errors and warnings in (one with the default bounds
        when not given); it outlives a kernel RESET. ``tables``: each channel's tool
        list and zero offsets at start (the operator data the service kept; None or
        absent: the configured ones); a kernel RESET keeps the tables it has then.
        ``idle_steps_max``: the decoder's endless-program guard ([limits]
        decoder_idle_steps_max; None: the default). ``rest_when_idle`` False: every cycle
        does its whole work, also at rest (the reference the resting cycles must equal,
        value for value; see ``_work``). ``repeatable`` (``[clock] samples =
        "repeatable"``, virtual clocks): kernel time stands still while the kernel rests
        (``_stands_still``), so that what clients send while it rests lands at the same
        cycle in every run, as between two steps of the step clock.

        The kernel owns its threads: the cycle thread and the workers (``workers``: the
        decoders and syntax checks), which run below the cycle's priority and which
        ``close`` cancels and joins."""
        self._tables: list[ToolingTables | None] = list(tables)
        self._check_max_errors = check_max_errors
        self._idle_steps_max = idle_steps_max
        self.workers = Workers()
        self.alarms = AlarmLog() if alarms is None else alarms
        self.config = config
        self.cycle_s = config.cycle_ms / 1000.0
        self.cycle_ns = round(config.cycle_ms * 1e6)
        self._clock = clock
        self._loader = loader
        self._exists = exists
        self._files = files
        self._save = save
        self._busy = False
        self._changed: list[bool] | None = None  # channels the cycle touched; None = all
        # The last cycle's work changed nothing and nothing is busy: the next cycle without
        # commands may be a resting one (``_rests``); its drives stay as published.
        self._quiet = False
        self._resting = False  # the last cycle rested: so do the next ones, until a command
        # a command was applied since the last whole cycle: the next cycle is a whole one
        # (a command is an event; ``_cruise_budget``)
        self._commanded = True
        # False: every stepped cycle that is not a resting one runs whole, never through
        # the cruise gate (the reference the equality tests compare the gate against)
        self.gate_stepped_cycles = True
        self._rest_when_idle = rest_when_idle
        self._drives_changed = True
        self.state = self._initial_state()
        self.stats = CycleStats(cycle_us=round(config.cycle_ms * 1000))
        # cycle lateness per cycle (realtime clock only): kept by the clock, read live
        self.lateness: LatenessHistogram | None = clock.lateness
        # what the realtime clock's cycle thread was granted (SCHED_FIFO, locked memory)
        self.realtime_grant: RealtimeGrant | None = getattr(clock, "grant", None)
        # the newest published snapshot; readers go through ``snapshot`` (a pin may hold
        # an older one for a thread); the cycle thread reads and writes this one only
        self._latest: Snapshot = self.state.snapshot(0, 0, time.time_ns(), self.stats)
        self._pin = _Pin()
        self.on_cycle_end: Callable[[Snapshot], None] | None = None
        # when ``on_cycle_end`` is set: the kernel time (ns) of the next cycle it must
        # see (None: none is due). Without it the hook sees every cycle and no cycles
        # run in bulk.
        self.next_observed_ns: Callable[[], int | None] | None = None
        self._event_speed = isinstance(clock, VirtualClock) and clock.event_speed
        self._repeatable = repeatable and isinstance(clock, VirtualClock)
        # no cycle has run since the last command applied between cycles (or since the
        # start): whether the kernel rests is then the state's alone (``_stands_still``)
        self._between_cycles = True
        self._queue: queue.SimpleQueue[Queued] = queue.SimpleQueue()
        self._waiting: deque[Queued] = deque()
        self._channel_index = {c.channel_id: k for k, c in enumerate(self.state.channels)}
        self._thread: threading.Thread | None = None
        self._closed = False
        # the replies of this cycle's commands while its work may still wait (virtual
        # clock), and the snapshot that shows the commands applied, published with them
        self._held: list[tuple[Done, Refusal | None]] = []
        self._applied_snapshot: Snapshot | None = None

    def _initial_state(self) -> KernelState:
        """State, axis parameters (clones resolved), switchover and channel runners as
        at start-up; the start-up messages go to the channels' error lists."""
        state = KernelState.from_config(self.config)
        state.alarms = self.alarms
        params, messages = initialise_axes(self.config)
        self.axis_params: dict[int, AxisParameters] = params
        state.axis_params = params  # shared: an update reaches runners and switchover
        self.switchover = Switchover(state, params)
        # Virtual and stepped time must give the same result cycle by cycle: GEO waits
        # for the decoder.
        self._deterministic = deterministic = isinstance(self._clock,
                                                         VirtualClock | StepClock)
        services = RunnerServices(
            machine=self.config, loader=self._loader, exists=self._exists,
            cycle_s=self.cycle_s, deterministic=deterministic, params=params,
            switchover=self.switchover, files=self._files, save=self._save,
            on_wait=self._reply_while_waiting, alarms=self.alarms, workers=self.workers,
            check_max_errors=self._check_max_errors, idle_steps_max=self._idle_steps_max)
        state.runners = [
            ChannelRunner(channel, cfg, services,
                          self._tables[k] if k < len(self._tables) else None)
            for k, (channel, cfg) in enumerate(zip(state.channels, self.config.channels,
                                                   strict=True))
        ]
        for message in messages:
            state.runners[message.channel_index].report(
                ErrorEntry(int(message.id), message.text, warning=message.warning)
            )
        for runner in state.runners:
            runner.initialise_channel()
        return state

    # ------------------------------------------------------------ service side

    @property
    def running(self) -> bool:
        """True while cycles run (ADS state RUN)."""
        return self.stats.running

    @property
    def snapshot(self) -> Snapshot:
        """The state as readers see it: the last published cycle, or the one this thread
        pinned with ``reading``."""
        pinned = self._pin.snapshot
        return self._latest if pinned is None else pinned

    def reading(self, snapshot: Snapshot | None = None) -> _Reading:
        """Pin ``snapshot`` (None: the newest published one) for the calling thread until
        the block ends: every read of ``snapshot`` on this thread (every object's getter)
        sees that cycle, however many cycles the kernel publishes meanwhile; other
        threads are not affected. Yields the pinned snapshot. A nested block keeps the
        outer pin."""
        return _Reading(self, snapshot)

    def channel_index(self, channel_id: int) -> int:
        """Position of the channel with logical id ``channel_id`` in the state."""
        return self._channel_index[channel_id]

    def submit(self, command: KernelCommand, done: Done) -> None:
        """Queue ``command``; ``done`` is called from the cycle thread once applied
        (at once, with a refusal, when the kernel is closed)."""
        if self._closed:
            done(Refusal(RefusalReason.NOT_READY, "the kernel is shut down"))
            return
        if isinstance(command, ResetChannel) and command.value:
            # a cycle that waits for the channel's decoder or syntax check (virtual
            # clock) stops waiting, so that the RESET is applied at the next cycle
            self.state.runners[command.channel_index].reset_pending.set()
        self._queue.put((command, done))

    def start(self) -> None:
        """Start the cycle thread."""
        run = self._run_stepped if isinstance(self._clock, StepClock) else self._run
        self._thread = threading.Thread(target=run, name="cnc-geo-cycle", daemon=True)
        self._thread.start()

    def close(self, timeout_s: float = 5.0) -> None:
        """Stop the cycle thread and wait for it, then cancel and join the workers, all
        within ``timeout_s``; queued commands are refused."""
        self._closed = True
        deadline = time.monotonic() + timeout_s
        if self._thread is not None:
            self._queue.put((_SHUTDOWN, _no_answer))
            self._thread.join(timeout_s)
            if self._thread.is_alive():
                log.error("cycle thread did not stop within %.1f s", timeout_s)
            self._thread = None
        self.workers.close(max(deadline - time.monotonic(), 0.0))

    # ------------------------------------------------------------ cycle thread

    def wait_for_command(self, timeout_s: float) -> None:
        """Block until a command arrives or ``timeout_s`` passes (the idle clock)."""
        try:
            self._waiting.append(self._queue.get(timeout=timeout_s))
        except queue.Empty:
            pass

    def _run(self) -> None:
        self._clock.start()
        # workers started from here on run below the cycle (and the service's threads)
        self.workers.priority = worker_priority(self.realtime_grant)
        try:
            while True:
                if not self.stats.running and not self._paused():
                    return
                if self._stands_still():
                    if not self._apply_between_cycles():
                        return
                    continue
                started = time.perf_counter()
                if self._event_speed and self._busy and self._run_in_bulk():
                    pass  # the bulk ran through a cycle an observer must see, published
                elif not self._cycle():
                    return
                self._between_cycles = False
                exec_us = int((time.perf_counter() - started) * 1e6)
                if exec_us > self.stats.exec_time_max_us:
                    self.stats.exec_time_max_us = exec_us
                self._clock.wait(self.state_has_work(), self.stats, self)
        except Exception as exc:  # a kernel fault is logged loudly; the service stays up
            log.exception("cycle thread failed; the kernel is stopped")
            self.alarms.raise_error(ErrorEntry(
                KERNEL_FAULT_ID, f"the kernel's cycle task failed ({exc!r}); the kernel is "
                "stopped: restart it (ADS WriteControl RESET)"), 0, AlarmClass.KERNEL)
            self.stats.running = False
            self._publish()

    def _stands_still(self) -> bool:
        """Repeatable samples on a virtual clock: no cycle runs while the kernel rests
        (the next cycle would change nothing but the time, ``_rests``), as under the step
        clock between two steps. Kernel time then does not run with the wall clock while
        nothing happens, so a subscription added and a program started while the kernel
        rests meet the same cycles in every run, however late the requests come."""
        if not self._repeatable or self._busy:
            return False
        if self._between_cycles:  # a command applied between cycles: the state decides
            return self._rests()
        return self._resting or (self._quiet and self._rests())

    def _apply_between_cycles(self) -> bool:
        """Wait for the next command and apply it between cycles, published without a
        cycle passing (as the step clock does between steps); False on shutdown."""
        command, done = self._next_command(block=True)
        if isinstance(command, _Shutdown):
            self._refuse_queued()
            return False
        result = self._apply(command)
        self._between_cycles = True
        self._publish()
        done(result)
        return True

    # ------------------------------------------------------------ step clock

    def _run_stepped(self) -> None:
        """The cycle thread under the step clock: no cycle runs until a client grants
        some (``StepCycles``, ``cnc_cycle_step_w``). Every other command is applied at
        once, between cycles, and published without a cycle passing: a write (a PLC's
        acknowledge) never waits for a step. The next granted cycle then starts with it
        applied, as a command applied at the start of that cycle would be."""
        self._clock.start()
        # workers started from here on run below the cycle (and the service's threads)
        self.workers.priority = worker_priority(self.realtime_grant)
        try:
            while True:
                if not self.stats.running and not self._paused():
                    return
                command, done = self._next_command(block=True)
                if isinstance(command, _Shutdown):
                    self._refuse_queued()
                    return
                if isinstance(command, StepCycles):
                    if not self._step(command, done):
                        return
                    continue
                result = self._apply(command)
                self._publish()
                done(result)
        except Exception:  # a kernel fault is logged loudly; the service stays up
            log.exception("cycle thread failed; the kernel is stopped")
            self.stats.running = False
            self._publish()

    def _step(self, step: StepCycles, done: Done) -> bool:
        """Run the granted cycles (commands that arrive meanwhile are applied at the
        start of the next, as under the other clocks); answer after the last one is
        published. Cycles that no observer needs (no notification due, no command
        queued) and that only move inside their segments run in bulk, as at event
        speed (``_run_in_bulk``: the queue is looked at between two bulks); the last
        granted cycle is always published. False when the kernel shuts down meanwhile."""
        assert isinstance(self._clock, StepClock)
        refusal = self._clock.check(step)
        if refusal is not None:
            done(refusal)
            return True
        first = self.stats.cycles
        last = first + step.cycles
        while self.stats.cycles < last:
            started = time.perf_counter()
            if self._run_in_bulk(last):
                pass  # the bulk ran through a cycle that had to be published
            elif not self._cycle():
                done(Refusal(RefusalReason.NOT_READY, "the kernel is shutting down"))
                return False
            exec_us = int((time.perf_counter() - started) * 1e6)
            if exec_us > self.stats.exec_time_max_us:
                self.stats.exec_time_max_us = exec_us
            if not self.stats.running:  # a STOP applied in the step's cycle ends it
                ran = self.stats.cycles - first
                done(Refusal(RefusalReason.NOT_READY,
                             f"the kernel stopped after {ran} of {step.cycles} cycles"))
                return True
        done(None)
        return True

    def _run_in_bulk(self, last: int | None = None) -> bool:
        """Run the cycles up to the next event in one step (event-speed virtual clock;
        the step clock's granted cycles up to ``last``, the step's last cycle, which is
        always published). An event is anything that can change the course of the run:
        a command in the queue or applied since the last whole cycle, and whatever makes
        a channel's next cycle more than cruising (a block end, a block to feed, a ramp,
        a link, see ``_cruise_budget``). The cycles run through ``_cruise``, the code
        every stepped cycle that only cruises runs too (``_work``), so the state after
        the bulk is the state after stepping the same cycles, bit for bit; the next
        cycle (the event's) then runs and is published as a cycle.

        A cycle an observer (the notification hub) must see is no event when it only
        cruises: the bulk runs through it and publishes it (issue 37: a due cycle of the
        subscriptions costs one snapshot, not a whole cycle's work). True when it did;
        False when the cycle the bulk stopped before still has to run."""
        if self._waiting or not self._queue.empty() or not self.stats.running:
            return False
        most = BULK_CYCLES_MAX
        due_cycle = last
        if self.on_cycle_end is not None:
            if self.next_observed_ns is None:
                return False  # the hook sees every cycle
            due_ns = self.next_observed_ns()
            if due_ns is not None:  # the bulk ends at the due cycle, or before it
                due = -(-due_ns // self.cycle_ns)
                due_cycle = due if last is None else min(due, last)
        if due_cycle is not None:
            most = min(most, due_cycle - self.stats.cycles)
        if most <= 1:
            return False  # one cycle: stepped (``_cycle``), through the same cruise
        if last is not None and (self._resting or (self._quiet and self._rests())):
            # the step clock's cycles of a machine at rest: all up to the due one
            self._count_cycles(most)
            self.stats.bulk_cycles += most
            self._rest(most)
        else:
            allowed = self._cruise_budget(most)
            if allowed is None:
                return False
            cycles, changed = allowed
            self._count_cycles(cycles)
            self.stats.bulk_cycles += cycles
            self._cruise(cycles, changed)
        if self.stats.cycles != due_cycle:
            # unpublished: the next cycle notes what it changes itself (a cycle that
            # applies commands copies every channel, as after any publication)
            self._changed, self._drives_changed = None, True
            return False
        # the due cycle cruised: publish it as stepping would (a channel whose cycles
        # change nothing keeps its frozen copy, as in a cycle's ``_work``)
        self._publish()
        return True

    def _cruise_budget(self, most: int) -> tuple[int, list[bool]] | None:
        """The gate of a bulk and of every stepped cycle: how many of the next cycles
        (at most ``most``) only cruise (no command applied since the last whole cycle,
        no link or suspend handshake, every channel's ``cruise_budget``), with the
        channels they change; None when the next cycle must be a whole one (or no
        channel moves)."""
        if self._commanded:
            return None
        moving = False
        changed = []
        for runner in self.state.runners:
            budget = runner.cruise_budget(most)
            changed.append(budget is not None)
            if budget is None:
                continue  # its cycles change nothing
            if budget <= 0:
                return None
            most, moving = budget, True
        if not moving or not self.switchover.at_rest():
            return None
        return most, changed

    def _cruise(self, cycles: int, changed: list[bool]) -> None:
        """Run ``cycles`` cycles that ``_cruise_budget`` allowed, counted already (the
        last is the current cycle): the channels cruise, the drives follow. One cycle
        of it is a stepped cycle (``_work``), more a bulk."""
        runners = self.state.runners
        time_s = self.stats.cycles * self.cycle_s
        for runner in runners:
            runner.cruise(cycles, time_s)
        self.state.drive_axes()
        switched = [False] * len(runners)
        self.switchover.update_offsets(switched)
        self._changed = [a or b for a, b in zip(changed, switched, strict=True)]
        self._busy, self._quiet = True, False

    def _count_cycles(self, cycles: int) -> None:
        """``cycles`` more cycles ran (or start): the counter, and the time stamp of what
        the current one raises."""
        cycles = self.stats.cycles = self.stats.cycles + cycles
        self.alarms.tick(cycles, cycles * self.cycle_ns)

    def _next_command(self, block: bool) -> Queued:
        if self._waiting:
            return self._waiting.popleft()
        return self._queue.get() if block else self._queue.get_nowait()

    def _cycle(self) -> bool:
        """One cycle; False when the kernel is shutting down.

        Commands are acknowledged only after the snapshot that shows their effect is
        published, so a read sent after a write's reply always sees the write. With the
        virtual clock the cycle's work may wait for a decoder (a run's first blocks):
        then the replies go out with a snapshot of the state as the commands left it
        (``_reply_while_waiting``), not after the wait.
        """
        applied: list[tuple[Done, Refusal | None]] = []
        shutting_down = False
        # (asked first: an empty queue's get raises, which costs more than an idle cycle)
        while self.stats.running and (self._waiting or not self._queue.empty()):
            try:
                command, done = self._next_command(block=False)
            except queue.Empty:
                break
            if isinstance(command, _Shutdown):
                shutting_down = True
                break
            applied.append((done, self._apply(command)))
        self._count_cycles(1)
        had_commands = bool(applied)
        if had_commands and self._deterministic and self.stats.running:
            self._held = applied  # answered at once should the work wait
            self._applied_snapshot = self._snapshot()
            applied = []
        if self.stats.running:
            self._work(had_commands)
        self._publish()
        held, self._held, self._applied_snapshot = self._held, [], None
        for done, result in applied + held:
            done(result)
        if shutting_down:
            self._refuse_queued()
            return False
        return True

    def _paused(self) -> bool:
        """Wait in STOP until RUN or RESET; False on shutdown."""
        while not self.stats.running:
            command, done = self._next_command(block=True)
            if isinstance(command, _Shutdown):
                self._refuse_queued()
                return False
            if isinstance(command, ControlCommand):
                result = self._apply(command)
                self._publish()
                done(result)
            else:
                if isinstance(command, ResetChannel):  # refused: no cycle may stop waiting for it
                    self.state.runners[command.channel_index].reset_pending.clear()
                done(Refusal(RefusalReason.NOT_READY, "the kernel is stopped (ADS state STOP)"))
        return True

    def _apply(self, command: KernelCommand) -> Refusal | None:
        # A command may change anything: the cycles after it do their whole work again
        # (the step clock applies commands between cycles, not in ``_cycle``).
        self._resting = self._quiet = False
        self._commanded = True
        try:
            if isinstance(command, ControlCommand):
                self._control(command.control)
                return None
            if isinstance(command, ResetCycleStats):
                if command.value:
                    self._reset_cycle_stats()
                return None
            if isinstance(command, StepCycles):  # the step loop takes steps before this
                return STEP_RUNNING if isinstance(self._clock, StepClock) else NOT_STEPPING
            return command.apply(self.state)
        except Exception:
            log.exception("command %r failed", command)
            return Refusal(RefusalReason.NOT_READY, f"the kernel failed to apply {command!r}")

    def _control(self, control: Control) -> None:
        match control:
            case Control.RUN:
                self.stats.running = True
            case Control.STOP:
                self.stats.running = False
            case Control.RESET:
                for runner in self.state.runners:
                    runner.reset()
                # operator data outlives a restart, as ISG's tool and zero point lists do:
                # new holders (the old decoders may still hold theirs) of the same tables
                self._tables = [ToolingTables(r.tables.tools, r.tables.zero_offsets,
                                              r.tables.tool_change_time_s)
                                for r in self.state.runners]
                self.alarms.restart()  # the start-up messages are raised again
                self.state = self._initial_state()
                self.stats.running = True
        return None

    def _reset_cycle_stats(self) -> None:
        stats = self.stats
        stats.overruns = stats.jitter_max_us = stats.exec_time_max_us = 0
        if self.lateness is not None:
            self.lateness.reset()

    def _refuse_queued(self) -> None:
        while True:
            try:
                command, done = self._next_command(block=False)
            except queue.Empty:
                return
            done(Refusal(RefusalReason.NOT_READY, "the kernel is shutting down"))

    def _reply_while_waiting(self) -> None:
        """A channel's cycle waits for its decoder or check (virtual clock): the
        replies of the commands this cycle applied go out now, with the snapshot taken
        after they were applied (no client request waits on the kernel's backlog). Reads
        see that snapshot until the cycle ends; the cycle's own publication (and its
        notifications) are as without the wait, so runs stay the same cycle by cycle."""
        if self._applied_snapshot is None:
            return
        self._latest, self._applied_snapshot = self._applied_snapshot, None
        held, self._held = self._held, []
        for done, result in held:
            done(result)

    def _snapshot(self) -> Snapshot:
        """The state as it is now, as readers see it (every channel copied unless
        ``_work`` noted which changed)."""
        cycle = self.stats.cycles
        # One wall-clock reading per cycle: the time the cycle's values were produced,
        # which notifications carry as their timestamp (kernel time is not wall time
        # under the virtual clock, nor under load).
        return self.state.snapshot(
            cycle, cycle * self.cycle_ns, time.time_ns(), self.stats, self._latest,
            self._changed, self._drives_changed,
        )

    def _publish(self) -> None:
        self._latest = snapshot = self._snapshot()
        self._changed = None
        self._drives_changed = True
        hook = self.on_cycle_end
        if hook is not None:
            hook(snapshot)

    def _work(self, applied_commands: bool) -> None:
        """The cycle's work: every channel's path, then the drives follow their axes.
        Notes which channels changed, so the snapshot copies only those (commands may
        have touched any channel: then all are copied).

        A resting cycle (``_rests``) only takes the time: the idle machine's cycles cost
        next to nothing, as the realtime clock runs them a thousand times a second."""
        if self._resting or (self._quiet and self._rests()):
            self._rest(1)
            return
        time_s = self.stats.cycles * self.cycle_s
        runners = self.state.runners
        allowed = self._cruise_budget(1) if self.gate_stepped_cycles else None
        if allowed is not None:  # the cycle only cruises: as one cycle of a bulk
            self._cruise(1, allowed[1])
            return
        self._commanded = False
        busy = False
        switched = [False] * len(runners)
        self.switchover.step(switched)
        changed = []
        for runner in runners:
            busy |= runner.cycle(time_s)
            changed.append(runner.touched)
        self.state.drive_axes()
        self.switchover.update_offsets(switched)
        self._busy = busy or self.switchover.in_progress
        if not applied_commands:
            self._changed = [a or b for a, b in zip(changed, switched, strict=True)]
        self._quiet = self._rest_when_idle and not (
            applied_commands or self._busy or any(changed) or any(switched))

    def _rest(self, cycles: int) -> None:
        """Run ``cycles`` resting cycles, counted already (one stepped, or the step
        clock's bulk): nothing but a command changes a machine at rest (``_rests``), so
        once one cycle rested the next ones do too, without asking again (``_apply``
        ends the rest); each channel only takes the time."""
        self._resting = True
        runners = self.state.runners
        time_s = self.stats.cycles * self.cycle_s
        for runner in runners:
            runner.cruise(cycles, time_s)  # a channel whose cycles change nothing: the time
        self._changed = [False] * len(runners)
        self._drives_changed = False

    def _rests(self) -> bool:
        """The next cycle's work would change nothing: the last cycle's changed nothing
        (``_quiet``), no link or suspend handshake is under way, and no channel runs,
        ramps its spindle or waits for a timed acknowledge (``cruise_budget`` None, the
        rule the event-speed clock's bulk follows). Every value a client can see is then
        the same after the cycle but the cycle counter and the times; a command, or
        anything that is not at rest, makes the next cycle a full one."""
        return self.switchover.at_rest() and all(
            runner.cruise_budget(1) is None for runner in self.state.runners)

    def state_has_work(self) -> bool:
        """True while a channel moves or decodes: the virtual clock runs cycles back to
        back; otherwise it may idle until the next command."""
        return self._busy
