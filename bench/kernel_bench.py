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


if __name__ == "__main__":
    result = measure()
    print(f"interpolator: {result['simulated_s']:.1f} s simulated, "
          f"{result['sim_per_wall']:.1f} simulated s per wall s (target >= 50)")
