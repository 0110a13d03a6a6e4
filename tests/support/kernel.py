"""The real kernel in-process on the virtual clock, for cycle-exact tests.

No service and no sockets: programs come from a dict, commands are submitted the way the
service submits them, and every published snapshot of channel 1 can be recorded, so a
test sees the path cycle by cycle.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass, field
from typing import Any

from cnc_objects.service.config import build_config
from cnc_objects.service.kernel.channel_mode import ChannelState
from cnc_objects.service.kernel.clock import VirtualClock
from cnc_objects.service.kernel.commands import ManualBlock, Refusal, SelectProgram, StartProgram
from cnc_objects.service.kernel.kernel import Kernel
from cnc_objects.service.kernel.state import Snapshot
from cnc_objects.service.machine_config import MachineConfig

_DONE_STATES = (ChannelState.READY, ChannelState.ERROR, ChannelState.SELECTED)


@dataclass(frozen=True)
class Sample:
    """Channel 1 at the end of one cycle."""

    cycle: int
    positions_mm: tuple[float, ...]
    path_velocity_mm_s: float
    state: int
    block_count: int


@dataclass
class Run:
    """The outcome of one program run."""

    final: Snapshot
    samples: list[Sample] = field(default_factory=list)

    @property
    def channel(self) -> Any:
        return self.final.channels[0]

    @property
    def positions_mm(self) -> tuple[float, ...]:
        return tuple(a.position_mm for a in self.channel.axes)


class KernelHarness:
    """A started kernel; use as a context manager."""

    def __init__(self, programs: dict[str, str] | None = None,
                 config: MachineConfig | None = None) -> None:
        self.programs = dict(programs or {})
        self.files: dict[str, bytes] = {}  # files the kernel wrote (its output area)
        self.config = config or build_config()
        self.kernel = Kernel(
            self.config, VirtualClock(self.config.cycle_ms / 1000.0),
            self._load, lambda name: name in self.programs, self._write,
            lambda name, data, replace: self._write(name, data, replace),
        )
        self._recording: list[Sample] | None = None
        self._finished = threading.Event()
        self._watching = False
        self._condition: tuple[Any, threading.Event] | None = None
        self.kernel.on_cycle_end = self._on_cycle

    def _load(self, name: str) -> str:
        return self.programs[name]

    def _write(self, name: str, data: bytes, replace: bool = False) -> None:
        self.files[name] = data if replace else self.files.get(name, b"") + data

    def __enter__(self) -> KernelHarness:
        self.kernel.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self.kernel.close()

    def _on_cycle(self, snap: Snapshot) -> None:
        ch = snap.channels[0]
        if self._recording is not None:
            self._recording.append(Sample(
                snap.cycle, tuple(a.position_mm for a in ch.axes), ch.path.path_velocity_mm_s,
                ch.state, ch.block.block_count,
            ))
        if self._watching and ch.state in _DONE_STATES:
            self._finished.set()
        condition = self._condition
        if condition is not None and condition[0](snap):
            condition[1].set()

    def watch(self, predicate: Any) -> threading.Event:
        """Call ``predicate(snapshot)`` for every cycle published from now on (on the
        cycle thread); the event is set once it returns True."""
        event = threading.Event()
        self._condition = (predicate, event)
        return event

    def wait_for(self, predicate: Any, timeout_s: float = 30.0) -> Snapshot:
        """Wait until ``predicate(snapshot)`` holds for a published cycle; that snapshot."""
        event = self.watch(predicate)
        if predicate(self.kernel.snapshot):
            event.set()
        assert event.wait(timeout_s), "the condition did not come true in time"
        self._condition = None
        return self.kernel.snapshot

    def command(self, command: Any, timeout_s: float = 10.0) -> Refusal | None:
        """Submit and wait until the cycle thread applied it."""
        done = threading.Event()
        result: list[Refusal | None] = []

        def finish(refusal: Refusal | None) -> None:
            result.append(refusal)
            done.set()

        self.kernel.submit(command, finish)
        assert done.wait(timeout_s), f"{command!r} was not applied in {timeout_s} s"
        return result[0]

    def _run(self, start: Any, record: bool, timeout_s: float) -> Run:
        self.begin(start, record)
        return self.wait(timeout_s)

    def begin(self, start: Any, record: bool = False, timeout_s: float = 10.0) -> None:
        """Apply ``start`` (START, a manual block) and return at once; ``wait`` ends it.
        START is applied in the cycle after it; a long LA_ON section is planned before
        that cycle ends (``timeout_s``)."""
        self._recording = [] if record else None
        self._finished.clear()
        applied = threading.Event()
        result: list[Refusal | None] = []

        def started(refusal: Refusal | None) -> None:  # cycle thread, after the publish
            result.append(refusal)
            # From here on a done state is the end of this run (it may end in this cycle).
            self._watching = refusal is None
            if refusal is None and self.kernel.snapshot.channels[0].state in _DONE_STATES:
                self._finished.set()
            applied.set()

        self.kernel.submit(start, started)
        assert applied.wait(timeout_s), "START was not applied"
        assert result[0] is None, result[0]

    def wait(self, timeout_s: float = 60.0) -> Run:
        """Wait until the run that ``begin`` started is READY or ERROR."""
        assert self._finished.wait(timeout_s), "the program did not end in time"
        self._watching = False
        samples, self._recording = self._recording or [], None
        while samples and samples[0].state != ChannelState.ACTIVE:
            samples.pop(0)  # cycles before START was applied
        return Run(self.kernel.snapshot, samples)

    def start(self, text: str, name: str = "test.nc", record: bool = False,
              timeout_s: float = 10.0) -> None:
        """Store, select and START ``text`` without waiting for its end."""
        self.programs[name] = text
        assert self.command(SelectProgram(0, name)) is None
        self.begin(StartProgram(0, True), record, timeout_s)

    def run(self, text: str, name: str = "test.nc", record: bool = False,
            timeout_s: float = 60.0) -> Run:
        """Store ``text`` as ``name``, select and START it, wait for READY or ERROR."""
        self.start(text, name, record, timeout_s)
        return self.wait(timeout_s)

    def home(self, timeout_s: float = 60.0) -> Run:
        """Home every axis of channel 1 (``G74`` in MDI): from then on its software
        limits are monitored (P-AXIS-00705, ISG's default)."""
        axes = " ".join(f"{a.name}1" for a in self.config.channels[0].axes)
        run = self.mdi(f"G74 {axes}", timeout_s=timeout_s)
        assert run.channel.errors.entries == (), run.channel.errors.entries
        return run

    def mdi(self, text: str, record: bool = False, timeout_s: float = 60.0) -> Run:
        """Run ``text`` as a manual block and wait until the channel is idle again."""
        return self._run(ManualBlock(0, text), record, timeout_s)
