"""Both virtual clocks over the wire (issue 30): ``--clock virtual`` (event speed, the
cycles between events in bulk) and ``--clock virtual-step`` (cycle by cycle) run the same
part to the same end, with a subscription on a moving position open meanwhile; the
cycle-exact proof is tests/service/kernel/test_event_speed_clock.py."""

from __future__ import annotations

import asyncio

import pytest

from cnc_objects.clients import AsyncClient
from cnc_objects.testing import serving

# long blocks (cruising) with corners, an arc, a dwell and an M function
PART = ("N10 G90 G17 G1 X20 F3000\nN20 Y10\nN30 G2 X40 Y10 I10 J0\nN40 G4 X0.2\n"
        "N50 M8\nN60 G1 X0 Y0 F6000\nN70 M9\nN80 M30\n")


async def _run(endpoint: str) -> tuple[dict[str, float], int, float, list[float]]:
    """(positions, block count, program time, samples of ch1.x) of one run of PART."""
    async with AsyncClient(endpoint, timeout_s=60) as c, AsyncClient(endpoint) as watcher:
        await c.upload("part.nc", PART.encode())
        samples: list[float] = []
        first, back = asyncio.Event(), asyncio.Event()

        async def watch() -> None:
            async for sample in watcher.subscribe("ch1.ax1.command_position_acs"):
                samples.append(sample.value)
                first.set()
                if sample.value == 0 and max(samples) > 0:
                    back.set()  # out and home again

        task = asyncio.create_task(watch())
        await asyncio.wait_for(first.wait(), 10)
        await c.run_program("part.nc")
        await c.wait_program(timeout_s=60)
        # the sample of X back at 0 comes within the subscription's interval (10 ms of
        # kernel time) after that cycle, which may be after the program's end
        await asyncio.wait_for(back.wait(), 10)
        status = await c.status()
        blocks = await c.read("ch1.actual_block_count")
        task.cancel()
        return status.positions_mm, blocks, status.program_time_s, samples


@pytest.mark.parametrize("clock", ["virtual", "virtual-step"])
def test_both_virtual_clocks_run_the_part_to_the_same_end(clock: str) -> None:
    with serving("--clock", clock) as service:
        positions, blocks, program_s, samples = asyncio.run(_run(service.endpoint))
    assert positions["X"] == 0.0 and positions["Y"] == 0.0
    assert blocks == 8
    # 20 + 10 + 31.4 + 44.7 mm at 50/100 mm/s, the dwell, corners' braking: about 1.5 s
    assert 1.3 < program_s < 2.5
    # the subscription saw the path move out to X40 and back (0.1 um increments)
    assert samples[0] == 0 and max(samples) == 400_000 and samples[-1] == 0
