"""The event-speed virtual clock is cycle-exact against stepping (issue 30).

The same program runs on a real kernel twice: on ``--clock virtual-step`` (every cycle
run whole and published, the cruise gate off) and on ``--clock virtual`` (the cycles between two events run in
bulk, unpublished). An observer stands for the notification hub: it asks for the cycles
of subscriptions at several cycle times, and client commands (feed override, feedhold,
START after it) are written at fixed cycles. Every value observed under the event clock
must be the stepping run's value at that cycle, bit for bit; every cycle the observer
asked for must be observed; every block change must be observed at the cycle it
happens at under stepping.

Hypothesis generates the programs (lines, arcs, look-ahead on/off, M functions, dwells)
and the scripts; ``--soak`` (make soak) runs many more examples.
"""

from __future__ import annotations

import math
import threading
from dataclasses import dataclass, field
from typing import Any

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from cnc_objects.service.config import build_config
from cnc_objects.service.kernel.channel_mode import ChannelState
from cnc_objects.service.kernel.clock import VirtualClock
from cnc_objects.service.kernel.commands import (
    Feedhold,
    SelectProgram,
    SetFeedOverride,
    StartProgram,
)
from cnc_objects.service.kernel.kernel import Kernel
from cnc_objects.service.kernel.state import Snapshot
from tests.reliability import scale

_DONE = (ChannelState.READY, ChannelState.ERROR)
_RUN_TIMEOUT_S = 120.0


def _observed(snap: Snapshot) -> tuple[Any, ...]:
    """What a client can see of channel 1 and the drives at the end of a cycle."""
    ch = snap.channels[0]
    return (
        tuple(a.position_mm for a in ch.axes), tuple(a.command_position_01um for a in ch.axes),
        ch.path_velocity_mm_s, ch.programmed_velocity_mm_s, ch.remaining_in_block_mm,
        ch.dist_prog_start_01um, ch.program_time_s, ch.block_count, ch.line, int(ch.state),
        ch.feed_override_per_mille, ch.spindle, ch.plc_functions,
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
        recording.values[cycle] = _observed(snap)
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


# ------------------------------------------------------------------ programs


@st.composite
def programs(draw: st.DrawFn) -> str:
    """A short program of lines and half circles in XY, with feeds, look-ahead on and
    off, M functions and dwells, ending with M30."""
    lines = ["G90 G17"]
    x = y = 0.0
    for _ in range(draw(st.integers(1, 6))):
        kind = draw(st.sampled_from(["line", "line", "arc", "la_on", "la_off", "m", "dwell"]))
        feed = draw(st.sampled_from([300, 600, 1500, 3000, 6000]))
        if kind == "line":
            x = draw(st.integers(-40, 40)) / 2
            y = draw(st.integers(-40, 40)) / 2
            lines.append(f"G1 X{x:g} Y{y:g} F{feed}")
        elif kind == "arc":
            r = draw(st.integers(1, 20)) / 2
            x += 2 * r
            lines.append(f"{draw(st.sampled_from(['G2', 'G3']))} X{x:g} Y{y:g} I{r:g} J0 F{feed}")
        elif kind == "la_on":
            lines.append("LA_ON")
        elif kind == "la_off":
            lines.append("LA_OFF")
        elif kind == "m":
            lines.append(draw(st.sampled_from(["M8", "M9", "M3 S1000", "M5"])))
        else:
            lines.append(f"G4 X{draw(st.integers(1, 30)) / 100:g}")
    lines += ["LA_OFF", "M30"]
    return "\n".join(lines) + "\n"


@st.composite
def scripts(draw: st.DrawFn) -> dict[int, list[Any]]:
    """Feed override changes and a feedhold with its START, at cycles of the run."""
    script: dict[int, list[Any]] = {}
    for _ in range(draw(st.integers(0, 3))):
        cycle = draw(st.integers(1, 3000))
        script.setdefault(cycle, []).append(SetFeedOverride(0, draw(st.integers(0, 1000))))
    if draw(st.booleans()):
        hold = draw(st.integers(1, 3000))
        script.setdefault(hold, []).append(Feedhold(0, True))
        script.setdefault(hold + draw(st.integers(1, 500)), []).append(StartProgram(0, True))
    last = max(script, default=0)
    script.setdefault(last + 1, []).append(SetFeedOverride(0, 1000))  # never stuck at 0
    return script


PERIODS = st.lists(st.sampled_from([1, 7, 10, 50, 100, 250, 1000]), min_size=0, max_size=3)


def test_event_speed_is_cycle_exact_against_stepping() -> None:
    """25 generated runs (the same ones each time); ``--soak`` (make soak) or
    ``CNC_SOAK=1``: 300 new ones."""
    soak = scale.soak()

    @settings(max_examples=300 if soak else 25, deadline=None, derandomize=not soak,
              suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
    @given(text=programs(), periods=PERIODS, script=scripts())
    def check(text: str, periods: list[int], script: dict[int, list[Any]]) -> None:
        assert_same(text, tuple(sorted(set(periods))), script)

    check()


def test_cruising_cycles_run_in_bulk() -> None:
    """A part of long blocks at F600, observed every 100 cycles: the event clock
    publishes a small share of its cycles, and every one equals stepping's."""
    text = "G90 G1 F600\n" + "".join(
        f"X{(k % 2) * 5} Y{k * 0.5:g}\n" for k in range(6)) + "M30\n"
    published = assert_same(text, (100,), {})
    stepped_cycles = run(text, False, (100,), {}).end_cycle
    assert published < stepped_cycles / 10


@st.composite
def short_block_programs(draw: st.DrawFn) -> str:
    """CAM-like runs of short blocks (issue 37): 20-200 moves of 0.01-0.1 mm in X, Y
    and Z at a high feed, so that several blocks end in one cycle, with LA_ON or not,
    and now and then an M function between two runs."""
    lines = ["G90 G17"]
    x = y = z = 0.0
    for _ in range(draw(st.integers(1, 3))):
        if draw(st.booleans()):
            lines.append("LA_ON")
        lines.append(f"G1 F{draw(st.sampled_from([1500, 3000, 6000, 12000]))}")
        heading = draw(st.integers(0, 359))
        for _ in range(draw(st.integers(20, 200))):
            heading += draw(st.integers(-20, 20))
            step = draw(st.integers(10, 100)) / 1000
            x += step * math.cos(math.radians(heading))
            y += step * math.sin(math.radians(heading))
            z += draw(st.integers(-10, 10)) / 1000
            lines.append(f"X{x:.4f} Y{y:.4f} Z{z:.4f}")
        lines.append("LA_OFF")
        if draw(st.booleans()):
            lines.append(draw(st.sampled_from(["M8", "M9", "G4 X0.01"])))
    lines.append("M30")
    return "\n".join(lines) + "\n"


def test_short_blocks_are_cycle_exact_against_stepping() -> None:
    """Programs of short blocks (several block ends per cycle, issue 37), with the
    subscription periods and scripts of the test above: 10 generated runs (``--soak``:
    100 new ones)."""
    soak = scale.soak()

    @settings(max_examples=100 if soak else 10, deadline=None, derandomize=not soak,
              suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
    @given(text=short_block_programs(), periods=PERIODS, script=scripts())
    def check(text: str, periods: list[int], script: dict[int, list[Any]]) -> None:
        assert_same(text, tuple(sorted(set(periods))), script)

    check()
