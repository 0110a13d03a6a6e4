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
from typing import Any

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from cnc_objects.service.kernel.commands import (
    Feedhold,
    SetFeedOverride,
    StartProgram,
)
from tests.reliability import scale
from tests.support.event_speed import (
    assert_same,
    run,
)

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
