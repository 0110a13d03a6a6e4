"""Interpolator speed: simulated seconds per wall second of the whole GEO cycle.

The real kernel in-process on the virtual clock (as fast as the CPU allows) runs a
3-axis program of lines and arcs; kernel time divided by wall time is the figure
(target >= 50). Everything a cycle does is in it: commands, SDA hand-over, planning,
interpolation, drives, snapshot.
"""

from __future__ import annotations

import statistics
import time

from tests.support.kernel import KernelHarness


def three_axis_program(passes: int = 40) -> str:
    """Zig-zag passes with arcs at the ends and a Z step per pass (about 60 s of motion)."""
    lines = ["%bench", "G90 G17 G0 X0 Y0 Z0", "G1 F6000"]
    for k in range(passes):
        y = 2.0 * k
        lines.append(f"G1 X100 Y{y:.3f} Z{-0.05 * k:.3f}")
        lines.append(f"G2 X100 Y{y + 1:.3f} I0 J0.5")
        lines.append(f"G1 X0 Y{y + 1:.3f}")
        lines.append(f"G3 X0 Y{y + 2:.3f} I0 J0.5")
    lines.append("G0 X0 Y0 Z0")
    lines.append("M30")
    return "\n".join(lines) + "\n"


def measure(runs: int = 3) -> dict:
    """Median simulated seconds per wall second over ``runs`` runs."""
    text = three_axis_program()
    ratios, sim = [], 0.0
    with KernelHarness() as harness:
        for _ in range(runs):
            harness.mdi("G90 G0 X0 Y0 Z0")
            started = time.perf_counter()
            run = harness.run(text, name="bench.nc", timeout_s=600)
            wall = time.perf_counter() - started
            assert run.channel.state == 3, run.channel.errors.entries  # READY
            sim = run.channel.path.program_time_s
            ratios.append(sim / wall)
    return {"simulated_s": sim, "sim_per_wall": statistics.median(ratios), "runs": ratios}


def five_axis_program(trafo: bool, step_mm: float, blocks: int) -> str:
    """Lines of ``step_mm`` along X and back, the table turning 0.1 degree per block
    (C), with or without ``#TRAFO ON`` (then the tip follows the lines)."""
    lines = ["%bench5", "G90 G17 G0 X0 Y0 Z0 A0 C0", "G1 F6000"]
    if trafo:
        lines.append("#TRAFO ON")
    per_pass = max(1, round(50.0 / step_mm))
    for k in range(1, blocks + 1):
        lap, at = divmod(k, per_pass)
        x = at * step_mm if lap % 2 == 0 else (per_pass - at) * step_mm
        lines.append(f"G1 X{x:.3f} Y{0.5 * lap:.3f} C{0.1 * k:.1f}")
    if trafo:
        lines.append("#TRAFO OFF")
    lines.append("M30")
    return "\n".join(lines) + "\n"


def _wall_per(harness: KernelHarness, text: str) -> tuple[float, float]:
    """Wall seconds per simulated cycle and per block of one run of ``text``."""
    harness.mdi("G90 G0 X0 Y0 Z0 A0 C0")
    started = time.perf_counter()
    run = harness.run(text, name="bench5.nc", timeout_s=600)
    wall = time.perf_counter() - started
    assert run.channel.state == 3, run.channel.errors.entries  # READY
    cycles = run.channel.path.program_time_s / harness.config.cycle_ms * 1000.0
    return wall / cycles, wall / text.count("\nG1 X")


def measure_trafo(runs: int = 3) -> dict:
    """``#TRAFO ON`` against the same program without it on ``--machine five-axis-ac``,
    runs paired: long blocks (5 mm, ~50 cycles each: the cost per cycle) and short
    ones (0.05 mm, under a cycle each: the cost per block)."""
    from cnc_objects.service.config import build_config
    from cnc_objects.service.machine_config import EmbeddedMachine

    config = build_config(machine=EmbeddedMachine.FIVE_AXIS_AC)
    cycle: dict[bool, list[float]] = {False: [], True: []}
    block: dict[bool, list[float]] = {False: [], True: []}
    with KernelHarness(config=config) as harness:
        for _ in range(runs):
            for trafo in (False, True):
                cycle[trafo].append(_wall_per(harness, five_axis_program(trafo, 5.0, 400))[0])
                block[trafo].append(
                    _wall_per(harness, five_axis_program(trafo, 0.05, 20_000))[1])
    us = {name: {k: statistics.median(v[k]) * 1e6 for k in (False, True)}
          for name, v in (("cycle", cycle), ("block", block))}
    return {"plain_us_per_cycle": us["cycle"][False], "trafo_us_per_cycle": us["cycle"][True],
            "cycle_ratio": us["cycle"][True] / us["cycle"][False],
            "plain_us_per_block": us["block"][False], "trafo_us_per_block": us["block"][True],
            "block_ratio": us["block"][True] / us["block"][False]}


if __name__ == "__main__":
    result = measure()
    print(f"interpolator: {result['simulated_s']:.1f} s simulated, "
          f"{result['sim_per_wall']:.1f} simulated s per wall s (target >= 50)")
