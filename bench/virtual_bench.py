"""Virtual time: simulated seconds per wall second of the whole service (issue 22).

A service on the virtual clock (1 ms cycle, the default machine) runs, through the client
library as ``cnc run --wait`` does, the pocket example and a generated part of one hour of
machining; each with no subscription and with 20 on-change subscriptions to values that
move (held by a second connection). The figure is ``ch1.program_time`` divided by the
wall time from START to READY. Targets (issue 22): >= 500x with none, >= 100x with 20
subscriptions.

Short blocks (issue 37, ``short_blocks``): the look-ahead bench's spiral of 10 000 blocks
of 0.05 mm and a CAM finishing program of about 115 000 blocks
(``bench/programs/cam_finish.py``), the same way, in a table of their own. Targets:
>= 100x with none, >= 50x with 20 subscriptions.
"""

from __future__ import annotations

import asyncio
import statistics
import sys
import time
from pathlib import Path

from cnc_objects.clients import AsyncClient
from tests.support.service import start_service

from .jitter_bench import WATCHED
from .lookahead_programs import spiral
from .programs import cam_finish

ROOT = Path(__file__).resolve().parents[1]
SUBSCRIPTIONS = 20


def one_hour_part(blocks: int = 7200) -> str:
    """A zigzag of 5 mm blocks at F600 (0.5 s each): one hour of machining, and more for
    the corners' stops."""
    lines = ["N1 G90 G17 G1 F600"]
    for k in range(blocks):
        lines.append(f"X{(k % 2) * 5} Y{(k // 2) % 20 * 0.5:.1f}")
    return "\n".join(lines) + "\nM30\n"


def programs() -> dict[str, bytes]:
    """The three parts, by name."""
    return {
        "pocket-la-on.nc": (ROOT / "docs/examples/pocket-la-on.nc").read_bytes(),
        "one-hour.nc": one_hour_part().encode(),
    }


async def _run(endpoint: str, name: str, data: bytes, subscriptions: int) -> tuple[float, float]:
    """(simulated s, wall s) of one run of ``name``."""
    async with AsyncClient(endpoint, timeout_s=600) as c, AsyncClient(endpoint) as watcher:
        await c.upload(name, data)
        await c.wait_mdi(await c.mdi("G90 G0 X0 Y0 Z0"))  # every run from the origin
        tasks = []
        opened = asyncio.Event()
        sampled: set[str] = set()

        async def watch(obj: str) -> None:
            async for _ in watcher.subscribe(obj):
                sampled.add(obj)
                if len(sampled) >= subscriptions:
                    opened.set()

        for obj in WATCHED[:subscriptions]:
            tasks.append(asyncio.create_task(watch(obj)))
        if subscriptions:
            await opened.wait()  # every subscription has its first sample
        started = time.perf_counter()
        await c.run_program(name)
        await c.wait_program(timeout_s=3600)
        wall_s = time.perf_counter() - started
        simulated_s = await c.read("ch1.program_time")
        for task in tasks:
            task.cancel()
        await c.delete_program(name)
    return simulated_s, wall_s


def main(runs: int) -> None:
    """Measure and print the table."""
    parts = programs()
    service = start_service("--clock", "virtual")
    rows = []
    try:
        for name, data in parts.items():
            for subscriptions in (0, SUBSCRIPTIONS):
                repeats = 1 if name == "one-hour.nc" else runs
                factors, sim = [], 0.0
                for _ in range(repeats):
                    sim, wall = asyncio.run(_run(service.endpoint, name, data, subscriptions))
                    factors.append(sim / wall)
                    print(f"virtual: {name} with {subscriptions} subscriptions: {sim:.1f} s "
                          f"in {wall:.2f} s ({sim / wall:.0f}x)", file=sys.stderr)
                rows.append((name, subscriptions, sim, statistics.median(factors), repeats))
    finally:
        service.stop()
    print("\nvirtual time, whole service (1 ms cycle): simulated s per wall s, START to READY")
    print(f"{'part':18} {'subscriptions':>13} {'machining s':>12} {'speed':>8}  target")
    for name, subscriptions, sim, factor, repeats in rows:
        target = 500 if subscriptions == 0 else 100
        print(f"{name:18} {subscriptions:13d} {sim:12.1f} {factor:7.0f}x  >= {target}: "
              f"{'met' if factor >= target else 'NOT met'}"
              f"{'' if repeats > 1 else ' (one run)'}")


SHORT_BLOCK_TARGETS = {0: 100, SUBSCRIPTIONS: 50}  # issue 37: speed by subscriptions


def short_block_programs() -> dict[str, bytes]:
    """The short-block parts, by name: the spiral and the CAM finishing program
    (generated here: the generator is the source, see its docstring)."""
    return {
        "spiral.nc": spiral().text.encode(),
        "cam-finish.nc": cam_finish.program().encode("ascii"),
    }


def short_blocks(runs: int) -> None:
    """Measure and print the short-block table (issue 37): each part with no and with 20
    on-change subscriptions, medians of ``runs``."""
    parts = short_block_programs()
    service = start_service("--clock", "virtual")
    rows = []
    try:
        for name, data in parts.items():
            for subscriptions in (0, SUBSCRIPTIONS):
                factors, sim = [], 0.0
                for _ in range(runs):
                    sim, wall = asyncio.run(_run(service.endpoint, name, data, subscriptions))
                    factors.append(sim / wall)
                    print(f"virtual: {name} with {subscriptions} subscriptions: {sim:.1f} s "
                          f"in {wall:.2f} s ({sim / wall:.1f}x)", file=sys.stderr)
                rows.append((name, len(data), subscriptions, sim, statistics.median(factors)))
    finally:
        service.stop()
    print("\nshort blocks, virtual time, whole service (1 ms cycle): simulated s per wall s, "
          f"START to READY, median of {runs}")
    print(f"{'part':14} {'bytes':>9} {'subscriptions':>13} {'machining s':>12} {'speed':>8}  "
          "target")
    for name, size, subscriptions, sim, factor in rows:
        target = SHORT_BLOCK_TARGETS[subscriptions]
        print(f"{name:14} {size:9d} {subscriptions:13d} {sim:12.1f} {factor:7.1f}x  "
              f">= {target}: {'met' if factor >= target else 'NOT met'}")
