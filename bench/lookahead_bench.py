"""Look-ahead benchmark: machining time on the kernel against the time-optimal limit.

``python -m bench.lookahead_bench [--quick] [--plot spiral.png [--plot-program NAME]
[--plot-only]]``

Each program of ``bench/lookahead_programs.py`` runs on the real kernel (virtual clock,
the default machine with only the look-ahead size changed): with LA_OFF and a buffer of
30, 120 and 190 blocks (FCT_LOOK_AHEAD_LOW / _STANDARD / _HIGH), and with LA_ON (the
program wrapped in LA_ON .. LA_OFF, standard buffer of 120). The figure is
``ch1.program_time`` divided by the optimum of the same planning model computed by the
separate reference implementation ``bench/reference_optimum.py`` (backward and forward
pass over the whole program at once, reading the same configuration).

Every run is also checked on its 1 ms samples: no axis faster than its maximum
velocity, no axis acceleration above its maximum inside a block (second differences of
three samples within one block), the path speed never above the programmed feed, and
the program ends exactly at its programmed end point.

Targets: LA_ON within 1 % of the optimum on every program; LA_OFF with 120 blocks
within 1 % wherever 120 blocks cover the stopping distance from the programmed feed.
The ratios are deterministic (virtual time); only the wall times vary.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from cnc_objects.service.config import build_config
from cnc_objects.service.machine_config import MachineConfig
from tests.support.kernel import KernelHarness, Run

from .lookahead_programs import BenchProgram, all_programs, spiral, with_la_on
from .reference_optimum import axis_limits, optimum_time_s, plan, speed_at

if TYPE_CHECKING:
    from matplotlib.figure import Figure

BUFFERS = {30: "FCT_LOOK_AHEAD_LOW", 120: "FCT_LOOK_AHEAD_STANDARD",
           190: "FCT_LOOK_AHEAD_HIGH"}
LA_ON_BUFFER = 120  # LA_ON runs with the standard buffer
TARGET = 1.01
_TOLERANCE = 1e-6  # relative allowance of the sample checks (rounding of positions)


@dataclass(frozen=True)
class Variant:
    """How a program runs: look-ahead buffer size and LA_ON or not."""

    buffer_blocks: int
    la_on: bool

    @property
    def label(self) -> str:
        return f"LA_ON/{self.buffer_blocks}" if self.la_on else f"LA_OFF/{self.buffer_blocks}"


VARIANTS = (Variant(30, False), Variant(120, False), Variant(190, False),
            Variant(LA_ON_BUFFER, True))


@dataclass
class Result:
    """One program run on one variant."""

    program: str
    variant: Variant
    program_time_s: float
    optimum_s: float
    violations: list[str]
    warnings: list[int]  # ids of the channel's warnings (50301: the buffer limits)
    end_error_mm: float
    wall_s: float
    run: Run | None = None

    @property
    def ratio(self) -> float:
        return self.program_time_s / self.optimum_s


def machine(buffer_blocks: int) -> MachineConfig:
    """The default machine with the look-ahead size ``buffer_blocks``."""
    config = build_config()
    channels = list(config.channels)
    channels[0] = channels[0].model_copy(
        update={"interpolator_function": BUFFERS[buffer_blocks]})
    return config.model_copy(update={"channels": tuple(channels)})


def run_program(program: BenchProgram, variant: Variant, keep_run: bool = False) -> Result:
    """Run ``program`` on the kernel with ``variant``; the figures and the checks."""
    config = machine(variant.buffer_blocks)
    text = with_la_on(program.text) if variant.la_on else program.text
    with KernelHarness(config=config) as harness:
        t0 = time.perf_counter()
        run = harness.run(text, name=f"{program.name}.nc", record=True, timeout_s=600.0)
        wall = time.perf_counter() - t0
    channel = run.channel
    violations = [f"error {e.id}: {e.text}" for e in channel.errors.entries if not e.warning]
    violations += check_samples(run, program, config)
    warnings = [e.id for e in channel.errors.entries if e.warning]
    end = program.elements[-1].end
    end_error = max(abs(a - b) for a, b in zip(run.positions_mm, end))
    return Result(program.name, variant, channel.path.program_time_s,
                  optimum_time_s(program.elements, axis_limits(config)), violations,
                  warnings, end_error, wall, run if keep_run else None)


def check_samples(run: Run, program: BenchProgram, config: MachineConfig) -> list[str]:
    """Limit violations seen on the 1 ms samples (empty: none)."""
    limits = axis_limits(config)
    cycle_s = config.cycle_ms / 1000.0
    pos = np.array([s.positions_mm for s in run.samples])
    if len(pos) < 3:
        return []
    found = []
    vel = np.diff(pos, axis=0) / cycle_s
    feed_max = max(e.feed_mm_min for e in program.elements) / 60.0
    for i, lim in enumerate(limits):
        worst = float(np.max(np.abs(vel[:, i])))
        if worst > lim.vel_max_mm_s * (1 + _TOLERANCE):
            found.append(f"axis {i + 1} at {worst:.3f} mm/s > {lim.vel_max_mm_s}")
    speeds = np.array([s.path_velocity_mm_s for s in run.samples])
    if speeds.max() > feed_max * (1 + _TOLERANCE):
        found.append(f"path speed {speeds.max():.3f} mm/s > F {feed_max:.3f}")
    counts = np.array([s.block_count for s in run.samples])
    inside = (counts[:-2] == counts[1:-1]) & (counts[1:-1] == counts[2:])  # one block
    acc = np.abs(np.diff(pos, n=2, axis=0)) / (cycle_s * cycle_s)
    for i, lim in enumerate(limits):
        if inside.any():
            worst = float(np.max(acc[inside, i]))
            if worst > lim.acc_max_mm_s2 * (1 + _TOLERANCE) + 1e-6:
                found.append(f"axis {i + 1} accelerates {worst:.1f} mm/s^2 inside a block "
                             f"> {lim.acc_max_mm_s2}")
    return found


def covers_stop(program: BenchProgram, buffer_blocks: int, config: MachineConfig) -> bool:
    """``buffer_blocks`` consecutive blocks anywhere in the program are longer than
    the distance to stop from the programmed feed (with the smallest axis acceleration)."""
    lengths = np.array([_length(e) for e in program.elements])
    if len(lengths) <= buffer_blocks:
        return True
    window = np.convolve(lengths, np.ones(buffer_blocks), mode="valid").min()
    feed = max(e.feed_mm_min for e in program.elements) / 60.0
    acc = min(lim.acc_max_mm_s2 for lim in axis_limits(config))
    return window >= feed * feed / (2.0 * acc)


def _length(element) -> float:
    if hasattr(element, "center"):
        radius = math.dist(element.start[:2], element.center[:2])
        return 2 * math.pi * radius if element.start == element.end else math.dist(
            element.start, element.end)
    return math.dist(element.start, element.end)


def speed_plot(path: str, program: BenchProgram | None = None) -> None:
    """Write ``speed_figure(program)`` (default: the spiral) as a PNG to ``path``."""
    from cnc_objects.clients.figure_png import png_bytes

    png = png_bytes(speed_figure(program or spiral()))
    with open(path, "wb") as out:
        out.write(png)


def speed_figure(program: BenchProgram) -> Figure:
    """The path speed over the path distance, 1200 x 600 px: the optimum, the LA_OFF/30
    and LA_ON runs on the kernel (their time against the optimum in the legend) and the
    programmed feed."""
    from cnc_objects.clients.figure_png import pixel_figure

    config = machine(LA_ON_BUFFER)
    optimum = plan(program.elements, axis_limits(config))
    grid_mm = np.linspace(0.0, optimum[-1].start_mm + optimum[-1].length_mm, 4000)
    fig = pixel_figure(1200, 600)
    ax = fig.add_subplot()
    ax.plot(grid_mm, speed_at(optimum, grid_mm), color="black", linewidth=3.0,
            label="optimum", zorder=1)
    # LA_ON first and wider, so that the LA_OFF line stays visible where they meet
    for variant, colour, width_pt in ((Variant(LA_ON_BUFFER, True), "tab:blue", 1.8),
                                      (Variant(30, False), "tab:red", 1.0)):
        result = run_program(program, variant, keep_run=True)
        pos_mm = np.array([s.positions_mm for s in result.run.samples])
        distance_mm = np.concatenate(
            ([0.0], np.cumsum(np.linalg.norm(np.diff(pos_mm, axis=0), axis=1))))
        speed_mm_s = np.array([s.path_velocity_mm_s for s in result.run.samples])
        ax.plot(distance_mm, speed_mm_s, color=colour, linewidth=width_pt,
                label=f"{variant.label}: {result.ratio:.4f} x optimum time", zorder=2)
    feed_mm_s = program.elements[0].feed_mm_min / 60.0
    ax.axhline(feed_mm_s, color="tab:gray", linestyle="--", linewidth=1.0,
               label=f"programmed feed F{program.elements[0].feed_mm_min:g}", zorder=0)
    ax.set_title(f"{program.name}: path speed over path distance")
    ax.set_xlabel("path distance (mm)")
    ax.set_ylabel("path speed (mm/s)")
    ax.set_ylim(bottom=0.0)
    ax.margins(x=0.01)
    ax.grid(True, alpha=0.3)
    fig.legend(loc="outside right upper")  # beside the axes: the curves fill them
    return fig


def table(results: list[Result], programs: list[BenchProgram]) -> str:
    """The results as a text table: one row per program, one ratio column per variant."""
    config = build_config()
    head = (f"{'program':<18} {'blocks':>7} {'optimum s':>10} "
            + " ".join(f"{v.label:>11}" for v in VARIANTS) + "  120 covers stop")
    rows = [head, "-" * len(head)]
    by = {(r.program, r.variant): r for r in results}
    for p in programs:
        cells = []
        optimum = None
        for v in VARIANTS:
            r = by.get((p.name, v))
            if r is None:
                cells.append(f"{'-':>11}")
                continue
            optimum = r.optimum_s
            flag = ("!" if r.violations or r.end_error_mm > 1e-9
                    else "w" if r.warnings else " ")
            cells.append(f"{r.ratio:>10.4f}{flag}")
        rows.append(f"{p.name:<18} {p.blocks:>7} {optimum or 0.0:>10.4f} " + " ".join(cells)
                    + f"  {'yes' if covers_stop(p, 120, config) else 'no'}")
    return "\n".join(rows)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true",
                        help="leave out the 5 and 20 mm circles (many chord blocks)")
    parser.add_argument("--plot", metavar="PNG", help="write a speed plot here")
    parser.add_argument("--plot-program", metavar="NAME", default="spiral",
                        help="the program of the speed plot (default: spiral)")
    parser.add_argument("--plot-only", action="store_true",
                        help="only the speed plot, no benchmark table")
    args = parser.parse_args(argv)
    programs = all_programs((1.0,) if args.quick else (1.0, 5.0, 20.0))
    by_name = {p.name: p for p in programs}
    if args.plot_program not in by_name:
        parser.error(f"--plot-program: one of {', '.join(by_name)}, not {args.plot_program!r}")
    if args.plot_only and not args.plot:
        parser.error("--plot-only needs --plot PNG")
    if args.plot_only:
        speed_plot(args.plot, by_name[args.plot_program])
        print(f"speed plot: {args.plot}")
        return 0
    results = []
    for program in programs:
        for variant in VARIANTS:
            results.append(run_program(program, variant))
    print(table(results, programs))
    print("ratio = ch1.program_time / optimum;  w: warning 50301 (the buffer limits the "
          "speed);  !: a limit or the end point was missed")
    bad = [r for r in results if r.violations or r.end_error_mm > 1e-9]
    for r in bad:
        print(f"{r.program} {r.variant.label}: end off by {r.end_error_mm:.3g} mm; "
              + "; ".join(r.violations))
    missed = [r for r in results if r.variant.la_on and r.ratio > TARGET]
    missed += [r for r in results if not r.variant.la_on and r.variant.buffer_blocks == 120
               and r.ratio > TARGET and covers_stop(
                   next(p for p in programs if p.name == r.program), 120, build_config())]
    for r in missed:
        print(f"target missed: {r.program} {r.variant.label} {r.ratio:.4f} > {TARGET}")
    wall = sum(r.wall_s for r in results)
    print(f"{len(results)} runs, {wall:.1f} s wall in the kernel runs")
    if args.plot:
        speed_plot(args.plot, by_name[args.plot_program])
        print(f"speed plot: {args.plot}")
    return 1 if bad or missed else 0


if __name__ == "__main__":
    sys.exit(main())
