"""A 3D finishing program as a CAM system writes it: a ball-end raster over a surface.

The part is an analytic free-form surface over a 40 x 30 mm patch,

    z(x, y) = 2 sin(x / 6) cos(y / 5) + 0.5 sin((x + y) / 2.5) - 3   (mm),

finished with a ball-end mill of radius 3 mm in a zig-zag raster along X, 0.15 mm
apart in Y (201 lines, about 115 000 blocks, 170 s of machining at F3000). The tool's
tip follows the surface offset by the ball's radius along the surface normal (contact
point + R n, minus R in Z): where the surface slopes in Y the tip's Y moves too, so a
block usually carries X, Y and Z. Points are placed as a CAM system's chord-tolerance
stepping does: the step along X is shorter where the surface bends (``_step_mm``),
between ``MIN_STEP_MM`` and ``MAX_STEP_MM`` (0.01-0.07 mm of X; the tip moves 0.02 to
0.1 mm, median 0.07 mm), which makes the short G1 blocks that real finishing programs
are made of. Coordinates are written
with 4 decimals, only the ones that changed (modal), as postprocessors do; the header
and footer are the usual ones (tool, spindle, coolant, safe height, rapid approach,
plunge, retract, M30) in the syntax our decoder reads.

The output is deterministic: the same text, byte for byte, on every machine (only
``math`` on fixed inputs, printed with fixed decimals). It is generated when the bench
runs instead of being committed: about 4 MB of text (0.1 s to generate) that this page describes exactly,
and a change of the generator cannot leave a stale file behind.

    python -m bench.programs.cam_finish [FILE]   # writes the program (default: stdout)
"""

from __future__ import annotations

import math
import sys

WIDTH_MM = 40.0  # X extent of the patch
DEPTH_MM = 30.0  # Y extent
STEPOVER_MM = 0.15  # raster line distance in Y
BALL_RADIUS_MM = 3.0
CHORD_TOLERANCE_MM = 0.0001  # the deviation a chord may have from the surface
MIN_STEP_MM, MAX_STEP_MM = 0.01, 0.07
FEED_MM_MIN = 3000.0
SPINDLE_RPM = 12000
SAFE_Z_MM = 5.0
DECIMALS = 4


def surface_mm(x: float, y: float) -> float:
    """The surface's height at (x, y)."""
    return 2.0 * math.sin(x / 6.0) * math.cos(y / 5.0) + 0.5 * math.sin((x + y) / 2.5) - 3.0


def _gradient(x: float, y: float) -> tuple[float, float]:
    """(dz/dx, dz/dy), in closed form."""
    c = 0.5 / 2.5 * math.cos((x + y) / 2.5)
    return (2.0 / 6.0 * math.cos(x / 6.0) * math.cos(y / 5.0) + c,
            -2.0 / 5.0 * math.sin(x / 6.0) * math.sin(y / 5.0) + c)


def _curvature_x(x: float, y: float) -> float:
    """|d2z/dx2|: how fast the raster line bends at x."""
    return abs(-2.0 / 36.0 * math.sin(x / 6.0) * math.cos(y / 5.0)
               - 0.5 / 6.25 * math.sin((x + y) / 2.5))


def _step_mm(x: float, y: float) -> float:
    """The step along X for the chord tolerance: a chord of length L over a curve of
    curvature k deviates by about k L^2 / 8."""
    k = _curvature_x(x, y)
    step = MAX_STEP_MM if k <= 0.0 else math.sqrt(8.0 * CHORD_TOLERANCE_MM / k)
    return min(MAX_STEP_MM, max(MIN_STEP_MM, step))


def tool_tip_mm(x: float, y: float) -> tuple[float, float, float]:
    """Where the ball-end's tip is when the ball touches the surface at (x, y)."""
    gx, gy = _gradient(x, y)
    norm = math.sqrt(gx * gx + gy * gy + 1.0)
    nx, ny, nz = -gx / norm, -gy / norm, 1.0 / norm
    r = BALL_RADIUS_MM
    return x + r * nx, y + r * ny, surface_mm(x, y) + r * nz - r


def _raster_xs(y: float, forward: bool) -> list[float]:
    """The contact points' x along one raster line, in the direction it is cut."""
    xs, x = [0.0], 0.0
    while x < WIDTH_MM:
        x = min(WIDTH_MM, x + _step_mm(x, y))
        xs.append(x)
    return xs if forward else xs[::-1]


class _Post:
    """The postprocessor: block numbers, modal coordinates with fixed decimals."""

    def __init__(self) -> None:
        self.lines: list[str] = []
        self._n = 0
        self._last: dict[str, str] = {}  # the modal words as last written (G, X, Y, Z)

    def block(self, words: str) -> None:
        self._n += 10
        self.lines.append(f"N{self._n} {words}")

    def move(self, g: str, point: tuple[float, float, float], feed: str = "") -> None:
        """A G0/G1 block with the coordinates that changed (none: no block)."""
        words = [] if self._last.get("G") == g else [g]
        for axis, value in zip("XYZ", point, strict=True):
            text = f"{value:.{DECIMALS}f}"
            if self._last.get(axis) != text:
                words.append(f"{axis}{text}")
                self._last[axis] = text
        if len(words) > (self._last.get("G") != g):
            self._last["G"] = g
            self.block(" ".join([*words, feed]).rstrip())


def program() -> str:
    """The whole program, ending with M30 and a newline."""
    post = _Post()
    post.lines += [
        "; cam_finish: 3D finishing, ball-end R3 raster over z = 2 sin(x/6) cos(y/5)"
        " + 0.5 sin((x+y)/2.5) - 3",
        f"; patch {WIDTH_MM:g} x {DEPTH_MM:g} mm, stepover {STEPOVER_MM} mm,"
        f" chord tolerance {CHORD_TOLERANCE_MM} mm, F{FEED_MM_MIN:g}"
        " (bench/programs/cam_finish.py)",
    ]
    post.block("G17 G90 G40")
    post.block("T1 D1 M6")
    post.block(f"S{SPINDLE_RPM} M3 M8")
    lines = round(DEPTH_MM / STEPOVER_MM) + 1
    first = tool_tip_mm(0.0, 0.0)
    post.move("G0", (first[0], first[1], SAFE_Z_MM))
    post.move("G1", first, f"F{FEED_MM_MIN / 4:g}")  # plunge at a quarter of the feed
    post.block(f"F{FEED_MM_MIN:g}")
    for k in range(lines):
        y = k * STEPOVER_MM
        for x in _raster_xs(y, forward=k % 2 == 0):
            post.move("G1", tool_tip_mm(x, y))
    post.move("G0", (*tool_tip_mm(WIDTH_MM if lines % 2 else 0.0, DEPTH_MM)[:2], SAFE_Z_MM))
    post.block("M9 M5")
    post.block("M30")
    return "\n".join(post.lines) + "\n"


def main() -> None:
    """Write the program to the file named on the command line, else to stdout."""
    text = program()
    if len(sys.argv) > 1:
        with open(sys.argv[1], "w", encoding="ascii") as out:
            out.write(text)
    else:
        sys.stdout.write(text)


if __name__ == "__main__":
    main()
