"""NC programs for the look-ahead benchmark, each with its independent geometry.

Every generator returns a ``BenchProgram``: the NC text (ISG syntax, axes X Y Z, start
at X0 Y0 Z0, ``M30`` at the end) and the same path as ``reference_optimum`` elements.
Coordinates are rounded to ``DECIMALS`` places before they are written, and the
elements carry exactly the values the text holds (the printed text parsed back), so
the reference plans the path the decoder reads.

Programs (all in the X/Y plane, Z stays 0):

* ``spiral``: approach line + 10,000 lines of 0.05 mm on an Archimedean spiral, F6000;
* ``pocket``: a zig-zag pocket with 90, 30 and 150 degree corners, F3000;
* ``alternating``: 0.01 mm and 10 mm lines alternating on a slowly turning polyline,
  F12000;
* ``circle_arcs(r)`` / ``circle_chords(r)``: a G2 and then a G3 full circle of radius r
  through the origin, as two arcs or as chords of 1 um, F6000.

``with_la_on(text)`` wraps a program for the enhanced look-ahead (``LA_ON`` before the
first motion block, ``LA_OFF`` before ``M30``).
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

from .reference_optimum import Arc, Element, Line

DECIMALS = 9  # printed decimals of every coordinate (1e-9 mm)
BLOCK_STEP = 10  # N10, N20, ...
CIRCLE_RADII_MM = (1.0, 5.0, 20.0)
CHORD_MM = 0.001
TWO_PI = 2.0 * math.pi

Point = tuple[float, float, float]


@dataclass(frozen=True)
class BenchProgram:
    """An NC program and its geometry (one element per motion block, in order)."""

    name: str
    text: str
    elements: list[Element]

    @property
    def blocks(self) -> int:
        """Number of motion blocks."""
        return len(self.elements)


def _number(value: float) -> tuple[str, float]:
    """``value`` as printed (``DECIMALS`` places) and the float the text stands for."""
    text = f"{value:.{DECIMALS}f}"
    return text, float(text)


class _Writer:
    """Writes motion blocks and collects the matching elements.

    The modal G word and F are written only when they change, as a CAM system would.
    """

    def __init__(self, name: str, comment: str) -> None:
        self.name = name
        self.lines = [f"; {name}: {comment}"]
        self.elements: list[Element] = []
        self.pos: Point = (0.0, 0.0, 0.0)  # the machine's start position
        self._g: str | None = None
        self._feed: float | None = None

    def _emit(self, g: str, axes: str, feed_mm_min: float) -> None:
        words = [f"N{BLOCK_STEP * (len(self.elements) + 1)}"]
        if g != self._g:
            words.append(g)
            self._g = g
        words.append(axes)
        if feed_mm_min != self._feed:
            words.append(f"F{feed_mm_min:g}")
            self._feed = feed_mm_min
        self.lines.append(" ".join(words))

    def line(self, x: float, y: float, feed_mm_min: float) -> None:
        """G01 to (x, y)."""
        (tx, vx), (ty, vy) = _number(x), _number(y)
        end = (vx, vy, 0.0)
        self._emit("G01", f"X{tx} Y{ty}", feed_mm_min)
        self.elements.append(Line(self.pos, end, feed_mm_min))
        self.pos = end

    def circle(self, cx: float, cy: float, ccw: bool, feed_mm_min: float) -> None:
        """A full circle (G2/G3) about (cx, cy), ending where it starts."""
        x, y = self.pos[0], self.pos[1]
        (tx, _), (ty, _) = _number(x), _number(y)
        (ti, vi), (tj, vj) = _number(cx - x), _number(cy - y)
        # the decoder takes I/J relative to the start: the centre is start + (I, J)
        self._emit("G03" if ccw else "G02", f"X{tx} Y{ty} I{ti} J{tj}", feed_mm_min)
        self.elements.append(Arc(self.pos, self.pos, (x + vi, y + vj), ccw=ccw,
                                 feed_mm_min=feed_mm_min))

    def program(self) -> BenchProgram:
        """The finished program (``M30`` appended)."""
        n = BLOCK_STEP * (len(self.elements) + 1)
        return BenchProgram(self.name, "\n".join([*self.lines, f"N{n} M30", ""]), self.elements)


def _polyline(writer: _Writer, points: Iterable[tuple[float, float]], feed_mm_min: float) -> None:
    for x, y in points:
        writer.line(x, y, feed_mm_min)


def spiral(blocks: int = 10_000, seg_mm: float = 0.05, feed_mm_min: float = 6000.0,
           start_radius_mm: float = 2.0, pitch_mm: float = 1.0) -> BenchProgram:
    """Approach line from the origin to (2, 0), then ``blocks`` lines of ``seg_mm`` (up
    to the printed rounding) with their vertices on the Archimedean spiral
    r = 2 mm + 1 mm per turn (counter-clockwise), all at ``feed_mm_min``: ``blocks`` + 1
    motion blocks."""
    w = _Writer("spiral", f"{blocks} lines of {seg_mm} mm on an Archimedean spiral, "
                f"F{feed_mm_min:g}")
    b = pitch_mm / TWO_PI  # dr/dtheta

    def point(theta: float) -> tuple[float, float]:
        r = start_radius_mm + b * theta
        return r * math.cos(theta), r * math.sin(theta)

    w.line(start_radius_mm, 0.0, feed_mm_min)  # approach
    theta, prev, points = 0.0, point(0.0), []
    for _ in range(blocks):
        # arc length per radian is hypot(r, b); then scale the angle step until the
        # chord is seg_mm (the chord is nearly proportional to the step: 3 rounds suffice)
        step = seg_mm / math.hypot(start_radius_mm + b * theta, b)
        for _ in range(3):
            step *= seg_mm / math.dist(prev, point(theta + step))
        theta += step
        prev = point(theta)
        points.append(prev)
    _polyline(w, points, feed_mm_min)
    return w.program()


def pocket(width_mm: float = 10.0, stepover_mm: float = 0.5, rows_per_zone: int = 76,
           feed_mm_min: float = 3000.0) -> BenchProgram:
    """Zig-zag pocket ``width_mm`` wide, cleared upwards (+Y) in two zones.

    Zone A (90 degree corners): rows along X, alternately +X and -X over the full width,
    joined by links of ``stepover_mm`` in +Y; every corner turns the path by 90 degrees.

    Zone B (30 and 150 degree corners): the links are inclined 30 degrees to the rows
    (length 2 * stepover, rising stepover, advancing sqrt(3) * stepover along X), so a
    +X row (from x = 0 to width - sqrt(3) s) turns by 30 degrees into its link (heading
    30 degrees), the link turns by 150 degrees into the -X row (from x = width to
    sqrt(3) s), which turns by 30 degrees into its link (heading 150 degrees), which
    turns by 150 degrees into the next +X row.

    Zone A starts at the origin with a +X row and has an even number of rows, so its
    last link ends at x = 0 where zone B's first +X row starts (a 90 degree corner).
    ``2 * rows_per_zone`` rows and as many links minus one: 303 blocks by default, a
    pocket of 10 x 75.5 mm.
    """
    if rows_per_zone % 2:
        raise ValueError("rows_per_zone must be even")
    w = _Writer("pocket", f"zig-zag pocket {width_mm:g} mm wide, 90/30/150 degree corners, "
                f"F{feed_mm_min:g}")
    s, shift = stepover_mm, math.sqrt(3.0) * stepover_mm
    points, y = [], 0.0
    for row in range(rows_per_zone):  # zone A
        x_end = width_mm if row % 2 == 0 else 0.0
        points += [(x_end, y), (x_end, y + s)]
        y += s
    for row in range(rows_per_zone):  # zone B
        if row % 2 == 0:
            points += [(width_mm - shift, y), (width_mm, y + s)]
        else:
            points += [(shift, y), (0.0, y + s)]
        y += s
    points.pop()  # the path ends with the last row, not with a link
    _polyline(w, points, feed_mm_min)
    return w.program()


def alternating(pairs: int = 150, short_mm: float = 0.01, long_mm: float = 10.0,
                turn_deg: float = 8.0, feed_mm_min: float = 12000.0) -> BenchProgram:
    """``pairs`` x (a ``short_mm`` line, then a ``long_mm`` line), every junction turning
    the path by ``turn_deg`` counter-clockwise, from the origin heading +X.

    With 8 degrees the heading goes round once every 45 junctions (a polygon of about
    36 mm radius, traversed about 6.7 times). The velocity-jump limit of such a
    junction, 20 mm/s / |change of an axis' direction component|, is 143 to 199 mm/s
    with the default machine: below F12000 = 200 mm/s at every junction, so they matter.
    """
    w = _Writer("alternating", f"{short_mm} mm and {long_mm} mm lines alternating, "
                f"turning {turn_deg:g} deg per junction, F{feed_mm_min:g}")
    turn = math.radians(turn_deg)
    x = y = heading = 0.0
    points = []
    for k in range(2 * pairs):
        length = short_mm if k % 2 == 0 else long_mm
        x += length * math.cos(heading)
        y += length * math.sin(heading)
        points.append((x, y))
        heading += turn
    _polyline(w, points, feed_mm_min)
    return w.program()


def circle_arcs(radius_mm: float, feed_mm_min: float = 6000.0) -> BenchProgram:
    """``G02 X0 Y0 I<r> J0`` then ``G03 X0 Y0 I<r> J0``: two full circles about (r, 0)
    through the origin, clockwise and then counter-clockwise."""
    w = _Writer(f"circle_arcs_r{radius_mm:g}",
                f"G2 and G3 full circle of radius {radius_mm:g} mm, F{feed_mm_min:g}")
    w.circle(radius_mm, 0.0, False, feed_mm_min)
    w.circle(radius_mm, 0.0, True, feed_mm_min)
    return w.program()


def circle_chords(radius_mm: float, chord_mm: float = CHORD_MM, feed_mm_min: float = 6000.0
                  ) -> BenchProgram:
    """The two circles of ``circle_arcs`` as G01 chords: round(2 pi r / chord_mm) chords
    per circle, the vertices on the circle (printed rounded), each circle ending exactly
    at the origin."""
    w = _Writer(f"circle_chords_r{radius_mm:g}",
                f"G2 and G3 full circle of radius {radius_mm:g} mm as {chord_mm:g} mm chords, "
                f"F{feed_mm_min:g}")
    n = round(TWO_PI * radius_mm / chord_mm)
    for sense in (-1.0, 1.0):  # clockwise, then counter-clockwise; both start at angle pi
        points = [(radius_mm + radius_mm * math.cos(math.pi + sense * TWO_PI * k / n),
                   radius_mm * math.sin(math.pi + sense * TWO_PI * k / n)) for k in range(1, n)]
        points.append((0.0, 0.0))  # close the circle exactly
        _polyline(w, points, feed_mm_min)
    return w.program()


def all_programs(radii_mm: Sequence[float] = CIRCLE_RADII_MM) -> list[BenchProgram]:
    """Every benchmark program: spiral, pocket, alternating, then arcs and chords per radius."""
    out = [spiral(), pocket(), alternating()]
    for r in radii_mm:
        out += [circle_arcs(r), circle_chords(r)]
    return out


_MOTION_LINE = re.compile(r"^\s*(N\d+\s+)?(G0?[0-3]\b|[XYZ])", re.IGNORECASE)
_END_LINE = re.compile(r"^\s*(N\d+\s+)?M30\b", re.IGNORECASE)


def with_la_on(text: str) -> str:
    """``text`` with a line ``LA_ON`` before the first motion block and ``LA_OFF``
    before the (last) ``M30`` line: the program for the enhanced look-ahead."""
    lines = text.split("\n")
    first = next(i for i, line in enumerate(lines) if _MOTION_LINE.match(line))
    end = max(i for i, line in enumerate(lines) if _END_LINE.match(line))
    return "\n".join([*lines[:first], "LA_ON", *lines[first:end], "LA_OFF", *lines[end:]])
