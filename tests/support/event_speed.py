"""Runs of one program in-process on two clocks, and their comparison cycle for cycle
(the event-speed clock against stepping)."""

from __future__ import annotations

import threading
from dataclasses import dataclass, field
from typing import Any

from cnc_objects.service.config import build_config
from cnc_objects.service.kernel.channel_mode import ChannelState
from cnc_objects.service.kernel.clock import VirtualClock
from cnc_objects.service.kernel.commands import (
    SelectProgram,
    StartProgram,
)
from cnc_objects.service.kernel.kernel import Kernel
from cnc_objects.service.kernel.state import Snapshot

_DONE = (ChannelState.READY, ChannelState.ERROR)

_RUN_TIMEOUT_S = 120.0


def observed_values(snap: Snapshot) -> tuple[Any, ...]:
    """What a client can see of channel 1 and the drives at the end of a cycle."""
    ch = snap.channels[0]
    return (
        tuple(a.position_mm for a in ch.axes), tuple(a.command_position_01um for a in ch.axes),
        *ch.path, ch.block.block_count, ch.block.line, int(ch.state),
        ch.switches.feed_override_per_mille, ch.spindle, ch.plc_functions,
        tuple((p.command_position_01um, p.actual_position_01um) for p in snap.physical_axes),
    )


@dataclass
class Recording:
    """The cycles one run published, with what they showed."""

    values: dict[int, tuple[Any, ...]] = field(default_factory=dict)
    end_cycle: int = 0


#: The (absolute) cycle at whose end the program is selected, and the one after which
#: START is written: the run starts at the same kernel time under both clocks (program
#: time is a difference of kernel times: its last bit depends on where they lie).
SELECT_CYCLE = 20

START_CYCLE = SELECT_CYCLE + 1


ORIGIN = START_CYCLE + 1  # the cycle that applies START: cycle 0 of a recording


def run(text: str, event_speed: bool, periods: tuple[int, ...],
        script: dict[int, list[Any]]) -> Recording:
    """Run ``text`` on a fresh kernel; the observer wants every cycle that is a multiple
    of one of ``periods`` (cycles) and writes ``script[cycle]`` at the end of ``cycle``
    (applied at the start of the next, as a client's write would be)."""
    config = build_config()
    kernel = Kernel(config, VirtualClock(config.cycle_ms / 1000.0, event_speed=event_speed),
                    {"p.nc": text}.__getitem__, lambda name: name == "p.nc")
    # the reference steps every cycle whole: the cruise gate (``_cruise_budget``, which
    # every other clock's stepped cycles pass through too) is what is proved here
    kernel.gate_stepped_cycles = event_speed
    recording = Recording()
    done = threading.Event()
    refusals: list[Any] = []

    def answer(refusal: Any) -> None:
        if refusal is not None:
            refusals.append(refusal)

    def on_cycle_end(snap: Snapshot) -> None:
        if snap.cycle == SELECT_CYCLE:
            kernel.submit(SelectProgram(0, "p.nc"), answer)
        elif snap.cycle == START_CYCLE:
            kernel.submit(StartProgram(0, True), answer)
        if snap.cycle < ORIGIN or done.is_set():
            return
        cycle = snap.cycle - ORIGIN
        recording.values[cycle] = observed_values(snap)
        for command in script.get(cycle, ()):
            kernel.submit(command, answer)
        if snap.channels[0].state in _DONE:
            recording.end_cycle = cycle
            done.set()

    kernel.on_cycle_end = on_cycle_end
    kernel.next_observed_ns = lambda: _shift(
        next_observed_ns_rel(kernel, ORIGIN, periods, script), kernel.cycle_ns)
    kernel.start()
    try:
        assert done.wait(_RUN_TIMEOUT_S), "the program did not end"
    finally:
        kernel.close()
    assert not refusals, refusals
    return recording


def next_observed_ns_rel(kernel: Kernel, origin: int, periods: tuple[int, ...],
                         script: dict[int, list[Any]]) -> int | None:
    """The next cycle (counted from ``origin``, the first one recorded) the observer
    wants: the next multiple of a period, or the next scripted write."""
    cycle = kernel.stats.cycles - origin
    if cycle < 0:
        return origin
    due = [cycle - cycle % p + p for p in periods]
    due += [c for c in script if c > cycle]
    return min(due) + origin if due else None


def _shift(cycle: int | None, cycle_ns: int) -> int | None:
    return None if cycle is None else cycle * cycle_ns


def assert_same(text: str, periods: tuple[int, ...], script: dict[int, list[Any]]) -> int:
    """Run both clocks and compare; the number of cycles the event clock published."""
    stepped = run(text, False, periods, script)
    bulk = run(text, True, periods, script)
    assert bulk.end_cycle == stepped.end_cycle, "the program ended at another cycle"
    # stepping publishes every cycle
    assert sorted(stepped.values) == list(range(stepped.end_cycle + 1))
    for cycle, values in bulk.values.items():
        expected = stepped.values[cycle]
        assert values == expected, f"cycle {cycle} differs: " + ", ".join(
            f"[{k}] {a!r} != {b!r}" for k, (a, b) in enumerate(zip(values, expected))
            if a != b)
    wanted = {c for p in periods for c in range(p, bulk.end_cycle + 1, p)} | {
        c for c in script if 0 < c <= bulk.end_cycle}
    assert wanted <= bulk.values.keys(), f"not observed: {sorted(wanted - bulk.values.keys())[:5]}"
    assert _changes(bulk) == _changes(stepped), "a block change was seen at another cycle"
    return len(bulk.values)


def _changes(recording: Recording) -> list[tuple[int, int, int]]:
    """(cycle, block count, line) of every observed change of the block count."""
    changes, last = [], None
    for cycle in sorted(recording.values):
        values = recording.values[cycle]
        if values[7] != last:
            changes.append((cycle, values[7], values[8]))
            last = values[7]
    return changes
