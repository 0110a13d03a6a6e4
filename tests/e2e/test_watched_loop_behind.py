"""A loop behind the event-speed kernel loses no due cycle (issue 37, "Watched at 200x").

Many subscriptions due every kernel cycle make each sampling pass cost more than the
kernel's cruising cycles, so the kernel gets ``PASSES_PENDING_MAX`` due cycles ahead of
the loop. The event-speed clock then waits until the loop has sampled most of them
instead of stepping single cycles that push the oldest kept ones out: with
``samples = "latest"`` too, a subscription sees every due cycle of a run, in order.
"""

from __future__ import annotations

import asyncio
import contextlib
from collections.abc import AsyncIterator
from typing import Any

from cnc_objects.clients import AsyncClient
from cnc_objects.testing import serving

CLOCK = "cnc_kernel_time_r"  # s; changes every kernel cycle (1 ms)
LOAD = 200  # further on-change subscriptions at 1 ms: a pass costs more than a cycle
MOVE = "G91 G1 X10 F600"  # one second of kernel time, cruising (run in bulk)
WATCHED_S = 1.2  # the move and a little rest after it


async def test_every_due_cycle_is_sampled_while_the_loop_is_behind() -> None:
    """Every kernel cycle of a move is due; each one's kernel time is sampled, 1 ms
    after the one before, however far behind the loop fell."""
    with serving("--clock", "virtual") as service:
        async with AsyncClient(service.endpoint, timeout_s=60) as c, \
                AsyncClient(service.endpoint, timeout_s=60) as load:
            names = [o.name for o in await load.browse("ch1.*") if "r" in o.access][:LOAD]
            async with contextlib.AsyncExitStack() as stack:
                heavy = [await stack.enter_async_context(
                    contextlib.aclosing(load.subscribe(n, cycle_ms=0))) for n in names]
                await asyncio.gather(*(anext(s) for s in heavy))  # all of them open
                clock: AsyncIterator[Any] = await stack.enter_async_context(
                    contextlib.aclosing(c.subscribe(CLOCK, cycle_ms=0, buffer_samples=None)))
                start_s = (await anext(clock)).value
                await c.mdi(MOVE)
                times_s = [start_s]
                while times_s[-1] < start_s + WATCHED_S:
                    times_s.append((await asyncio.wait_for(anext(clock), 30)).value)
    steps_us = {round((b - a) * 1e6) for a, b in zip(times_s, times_s[1:])}
    assert steps_us == {1000}, sorted(steps_us)[:10]
