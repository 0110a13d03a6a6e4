"""Path planner benchmark: streamed look-ahead against the whole-program optimum.

``python -m bench.planner_bench [--runs N]``

Programs (3 axes X, Y, Z):

* spiral: 10,000 lines of 0.05 mm on an Archimedean spiral (radius 2 mm growing 1 mm
  per turn) at F6000 (100 mm/s), the classic "short blocks" case;
* pocket: a 120 x 80 mm rectangular pocket, 10 mm deep in two 5 mm passes, cleared
  zig-zag with a 4 mm step-over at F6000, 90 degree corners, G0 between the passes.

Axis limits for every axis: V = 500 mm/s, A = 5000 mm/s^2, dV = 50 mm/s (the velocity
jump at a 90 degree corner therefore limits the corner speed to 50 mm/s). Cycle 1 ms.

Figures (median of ``--runs`` runs; wall time is noisy on small VMs):

* ``*_ratio``: machining time with the streamed look-ahead (``buffer_blocks`` 120,
  blocks pushed as slots free up, ``PathExecutor`` run cycle by cycle) divided by the
  whole-program plan of the same model (``plan_time_optimal``). Target <= 1.01.
* ``*_sim_per_wall``: simulated seconds per wall second of that run (push + step).
* ``cruise_step_us``: wall time of one ``step()`` while cruising on a long 3-axis line.
* ``fast_spiral_ratio_buffer*``: the spiral at F18000, where braking from 300 mm/s
  needs 9 mm (180 blocks): with a buffer that does not cover it the path must slow down.
* ``line_sim_per_wall``: simulated seconds per wall second on a program of long lines.
"""

from __future__ import annotations

import argparse
import math
import statistics
import sys
import time

from cnc_objects.service.kernel.nc.blocks import Block, Motion, MotionKind, SourceRef, StopKind
from cnc_objects.service.kernel.path import AxisDynamics, PathExecutor, plan_time_optimal

DYNAMICS = [AxisDynamics(vel_max_mm_s=500.0, acc_max_mm_s2=5000.0, vel_jump_mm_s=50.0)] * 3
CYCLE_S = 0.001


def _block(n: int, kind: MotionKind, start, end, feed_mm_min: float, **kw) -> Block:
    feed = math.inf if kind == MotionKind.RAPID else feed_mm_min / 60.0
    return Block(SourceRef("bench.nc", n), n, Motion(kind, tuple(start), tuple(end), feed, **kw))


def spiral_blocks(n: int = 10_000, seg_mm: float = 0.05, feed_mm_min: float = 6000) -> list[Block]:
    """``n`` lines of about ``seg_mm`` on an Archimedean spiral r = 2 mm + 1 mm/turn."""
    r0, pitch = 2.0, 1.0
    b = pitch / (2.0 * math.pi)
    theta = 0.0
    prev = (r0, 0.0, 0.0)
    blocks = []
    for k in range(n):
        r = r0 + b * theta
        theta += seg_mm / math.hypot(r, b)
        r = r0 + b * theta
        point = (r * math.cos(theta), r * math.sin(theta), 0.0)
        blocks.append(_block(k + 1, MotionKind.LINEAR, prev, point, feed_mm_min))
        prev = point
    return blocks


def pocket_blocks(width_mm: float = 120.0, height_mm: float = 80.0, depth_mm: float = 10.0,
                  pass_mm: float = 5.0, stepover_mm: float = 4.0,
                  feed_mm_min: float = 6000) -> list[Block]:
    """Zig-zag clearing of a rectangular pocket, several depth passes, G0 in between."""
    blocks: list[Block] = []
    pos = (0.0, 0.0, 5.0)

    def move(kind, target, feed=feed_mm_min):
        nonlocal pos
        blocks.append(_block(len(blocks) + 1, kind, pos, target, feed))
        pos = target

    z = 0.0
    while z > -depth_mm + 1e-9:
        z = max(z - pass_mm, -depth_mm)
        move(MotionKind.RAPID, (0.0, 0.0, 5.0))
        move(MotionKind.LINEAR, (0.0, 0.0, z), feed_mm_min / 4)  # plunge
        y, right = 0.0, True
        while True:
            move(MotionKind.LINEAR, (width_mm if right else 0.0, y, z))
            if y >= height_mm - 1e-9:
                break
            y = min(y + stepover_mm, height_mm)
            move(MotionKind.LINEAR, (width_mm if right else 0.0, y, z))
            right = not right
        move(MotionKind.RAPID, (pos[0], pos[1], 5.0))
    blocks.append(Block(SourceRef("bench.nc", len(blocks) + 1), len(blocks) + 1,
                        stop=StopKind.PROGRAM_END))
    return blocks


def _run(blocks: list[Block], buffer_blocks: int, cycle_s: float) -> tuple[int, float]:
    """(cycles until idle, wall seconds) of one executor run."""
    start = next(b.motion for b in blocks if b.motion is not None).start_mm
    ex = PathExecutor(DYNAMICS, start, cycle_s=cycle_s, buffer_blocks=buffer_blocks)
    k, n, cycles = 0, len(blocks), 0
    t0 = time.perf_counter()
    while True:
        slots = ex.free_slots()
        while slots and k < n:
            ex.push(blocks[k])
            k += 1
            slots -= 1
            if k == n:
                ex.close()
        result = ex.step(1.0)
        cycles += 1
        if result.stopped_at is not None:
            ex.resume()  # M30: count the program as done
        if k == n and ex.idle:
            break
    return cycles, time.perf_counter() - t0


def machining_time_s(blocks: list[Block], buffer_blocks: int = 120, cycle_s: float = CYCLE_S) -> float:
    """Machining time of the streamed executor: cycles until idle times the cycle."""
    return _run(blocks, buffer_blocks, cycle_s)[0] * cycle_s


def optimal_time_s(blocks: list[Block]) -> float:
    """The same model planned over the whole program at once."""
    return plan_time_optimal(blocks, DYNAMICS)


def cruise_step_us(length_mm: float = 2000.0, repeats: int = 20_000) -> float:
    """Wall time (us) of one step() while cruising on a long 3-axis line."""
    start = (0.0, 0.0, 0.0)
    end = (length_mm, length_mm / 2, length_mm / 4)
    ex = PathExecutor(DYNAMICS, start, cycle_s=CYCLE_S)
    ex.push(_block(1, MotionKind.LINEAR, start, end, 12000))
    ex.close()
    step = ex.step
    for _ in range(200):  # accelerate to cruise
        step(1.0)
    t0 = time.perf_counter()
    for _ in range(repeats):
        step(1.0)
    return (time.perf_counter() - t0) / repeats * 1e6


def line_program(n: int = 40) -> list[Block]:
    """``n`` long 3-axis lines (zig-zag, 200 mm each) at F12000."""
    blocks, pos = [], (0.0, 0.0, 0.0)
    for k in range(n):
        target = (200.0 if k % 2 == 0 else 0.0, 5.0 * (k + 1), -0.5 * (k + 1))
        blocks.append(_block(k + 1, MotionKind.LINEAR, pos, target, 12000))
        pos = target
    return blocks


def measure(runs: int = 3) -> dict:
    """Ratios, times and speeds; each figure the median over ``runs`` runs."""
    out: dict = {}
    for name, blocks in (("spiral", spiral_blocks()), ("pocket", pocket_blocks()),
                         ("line", line_program())):
        t0 = time.perf_counter()
        optimal = optimal_time_s(blocks)
        plan_wall = time.perf_counter() - t0
        results = [_run(blocks, 120, CYCLE_S) for _ in range(runs)]
        cycles = results[0][0]
        wall = statistics.median(w for _, w in results)
        out[f"{name}_blocks"] = len(blocks)
        out[f"{name}_time_s"] = cycles * CYCLE_S
        out[f"{name}_optimal_s"] = optimal
        out[f"{name}_ratio"] = cycles * CYCLE_S / optimal
        out[f"{name}_wall_s"] = wall
        out[f"{name}_sim_per_wall"] = cycles * CYCLE_S / wall
        out[f"{name}_plan_wall_s"] = plan_wall
    blocks = spiral_blocks()
    for size in (30, 190):
        out[f"spiral_ratio_buffer{size}"] = machining_time_s(blocks, size) / out["spiral_optimal_s"]
    # F18000: braking from 300 mm/s takes 9 mm = 180 segments, more than 30 or 120 cover
    fast = spiral_blocks(feed_mm_min=18000)
    out["fast_spiral_optimal_s"] = optimal_time_s(fast)
    for size in (30, 120, 190, 400):
        out[f"fast_spiral_ratio_buffer{size}"] = (machining_time_s(fast, size)
                                                  / out["fast_spiral_optimal_s"])
    out["cruise_step_us"] = statistics.median(cruise_step_us() for _ in range(max(runs, 3)))
    return out


def main(argv: list[str] | None = None) -> int:
    """Print the figures."""
    parser = argparse.ArgumentParser(prog="python -m bench.planner_bench",
                                     description=__doc__.split("\n")[0])
    parser.add_argument("--runs", type=int, default=3)
    args = parser.parse_args(argv)
    res = measure(args.runs)
    print(f"axes: V=500 mm/s, A=5000 mm/s^2, dV=50 mm/s; cycle {CYCLE_S * 1e3:g} ms; "
          f"buffer 120 blocks; median of {args.runs} runs\n")
    print(f"{'program':8} {'blocks':>7} {'streamed s':>11} {'optimal s':>10} {'ratio':>8} "
          f"{'wall s':>7} {'sim s/wall s':>13}  target ratio <= 1.01")
    for name in ("spiral", "pocket", "line"):
        ratio = res[f"{name}_ratio"]
        print(f"{name:8} {res[f'{name}_blocks']:7d} {res[f'{name}_time_s']:11.3f} "
              f"{res[f'{name}_optimal_s']:10.4f} {ratio:8.5f} {res[f'{name}_wall_s']:7.2f} "
              f"{res[f'{name}_sim_per_wall']:13.1f}  {'met' if ratio <= 1.01 else 'NOT met'}")
    print(f"\nspiral ratio with buffer 30: {res['spiral_ratio_buffer30']:.5f}, "
          f"190: {res['spiral_ratio_buffer190']:.5f}")
    print("spiral at F18000 (braking distance 9 mm = 180 blocks), ratio by buffer size: "
          + ", ".join(f"{n}: {res[f'fast_spiral_ratio_buffer{n}']:.4f}" for n in (30, 120, 190, 400)))
    print(f"whole-program plan of the spiral: {res['spiral_plan_wall_s'] * 1e3:.0f} ms wall")
    print(f"step() while cruising on a 3-axis line: {res['cruise_step_us']:.2f} us "
          f"({1e-3 / (res['cruise_step_us'] * 1e-6):.0f} simulated s per wall s at 1 ms)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
