"""Hypothesis strategies for the equality properties (issue 37, "Equality stays proved").

``mixed_programs`` writes what CAM output looks like next to what a hand-written program
does: runs of short blocks (0.01-0.1 mm lines in X, Y and Z, and short arcs) at high
feeds, so that several blocks end in one cycle, between long lines, half circles,
dwells and M functions, with look-ahead on or off. ``scripts`` are client writes at
fixed cycles of the run (feed override, a feedhold and its START), as plain tuples so
that they cross a process boundary (``to_commands`` makes the kernel's commands).
"""

from __future__ import annotations

import math
from typing import Any

from hypothesis import strategies as st

#: A client write at the end of a cycle of the run: (cycle, kind, argument), kind one of
#: ``override`` (per mille), ``hold``, ``start``.
Write = tuple[int, str, int]

FEEDS_MM_MIN = (300, 600, 1500, 3000, 6000, 12000)


@st.composite
def short_run(draw: st.DrawFn, start: tuple[float, float, float]) -> tuple[list[str], tuple[
        float, float, float]]:
    """20-120 short moves from ``start``: lines of 0.01-0.1 mm turning by up to 20
    degrees each, or arcs of 0.02-0.2 mm chord in XY; the lines and the end point."""
    x, y, z = start
    lines = [f"G1 F{draw(st.sampled_from(FEEDS_MM_MIN[2:]))}"]
    heading = draw(st.integers(0, 359))
    arcs = draw(st.booleans())
    for _ in range(draw(st.integers(20, 120))):
        heading += draw(st.integers(-20, 20))
        if arcs and draw(st.integers(0, 3)) == 0:
            r = draw(st.integers(1, 10)) / 100  # a half circle of chord 2 r along X
            x += 2 * r
            lines.append(f"{draw(st.sampled_from(['G2', 'G3']))} X{x:.4f} Y{y:.4f} "
                         f"I{r:.4f} J0")
            lines.append("G1")
            continue
        step = draw(st.integers(10, 100)) / 1000
        x += step * math.cos(math.radians(heading))
        y += step * math.sin(math.radians(heading))
        z += draw(st.integers(-10, 10)) / 1000
        lines.append(f"X{x:.4f} Y{y:.4f} Z{z:.4f}")
    return lines, (x, y, z)


@st.composite
def mixed_programs(draw: st.DrawFn, max_pieces: int = 5) -> str:
    """A program of 1-``max_pieces`` pieces (short-block runs, long lines, half circles,
    dwells, M functions, look-ahead switched), at least one short-block run, ending with
    LA_OFF and M30."""
    lines = ["G90 G17"]
    at = (0.0, 0.0, 0.0)
    kinds = draw(st.lists(st.sampled_from(
        ["short", "short", "line", "arc", "la_on", "la_off", "m", "dwell"]),
        min_size=1, max_size=max_pieces))
    if "short" not in kinds:
        kinds.insert(draw(st.integers(0, len(kinds))), "short")
    for kind in kinds:
        feed = draw(st.sampled_from(FEEDS_MM_MIN))
        x, y, z = at
        if kind == "short":
            run, at = draw(short_run(at))
            lines += run
        elif kind == "line":
            at = (draw(st.integers(-40, 40)) / 2, draw(st.integers(-40, 40)) / 2, z)
            lines.append(f"G1 X{at[0]:.4f} Y{at[1]:.4f} F{feed}")
        elif kind == "arc":
            r = draw(st.integers(1, 20)) / 2
            at = (x + 2 * r, y, z)
            lines.append(f"{draw(st.sampled_from(['G2', 'G3']))} X{at[0]:.4f} Y{y:.4f} "
                         f"I{r:g} J0 F{feed}")
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
def scripts(draw: st.DrawFn, last_cycle: int = 3000) -> list[Write]:
    """Feed override changes and a feedhold with its START, at cycles 1..``last_cycle``
    of the run; the last write sets the override back to 100 % (never stuck at 0)."""
    writes: list[Write] = [(draw(st.integers(1, last_cycle)), "override",
                            draw(st.integers(0, 1000))) for _ in range(draw(st.integers(0, 3)))]
    if draw(st.booleans()):
        hold = draw(st.integers(1, last_cycle))
        writes += [(hold, "hold", 1), (hold + draw(st.integers(1, 500)), "start", 1)]
    writes.append((max((w[0] for w in writes), default=0) + 1, "override", 1000))
    return sorted(writes)


#: Subscription periods of the in-process observer (cycles)
PERIODS = st.lists(st.sampled_from([1, 7, 10, 50, 100, 250, 1000]), min_size=0,
                   max_size=3).map(lambda p: tuple(sorted(set(p))))


def to_commands(writes: list[Write]) -> dict[int, list[Any]]:
    """The kernel's commands of ``writes``, by cycle (``test_event_speed_clock.run``'s
    script)."""
    from cnc_objects.service.kernel.commands import Feedhold, SetFeedOverride, StartProgram

    make = {"override": lambda v: SetFeedOverride(0, v), "hold": lambda _: Feedhold(0, True),
            "start": lambda _: StartProgram(0, True)}
    script: dict[int, list[Any]] = {}
    for cycle, kind, value in writes:
        script.setdefault(cycle, []).append(make[kind](value))
    return script
