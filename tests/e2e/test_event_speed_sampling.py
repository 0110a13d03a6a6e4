"""Under the event-speed clock a subscription reads the cycle that was due, not a later
one (issue 37): the kernel keeps each due cycle's snapshot for the pass and runs on in
bulk to the next due cycle, so samples lie on the subscription's grid of kernel time."""

from __future__ import annotations

import contextlib

from cnc_objects.clients import AsyncClient
from cnc_objects.testing import serving

SAMPLES = 40
CYCLE_MS = 10
CLOCK = "cnc_kernel_time_r"  # s; changes every kernel cycle (1 ms)
LONG_MOVE = "G90 G1 X500 F100"  # five minutes of kernel time, cruising (run in bulk)


async def test_samples_are_the_due_cycles_while_the_kernel_runs_ahead() -> None:
    """Every sample after the first (the current value) is the kernel time of a due
    cycle: a multiple of the subscription's 10 ms, however far the kernel ran meanwhile."""
    with serving("--clock", "virtual") as service:
        async with AsyncClient(service.endpoint) as c:
            await c.mdi(LONG_MOVE)
            samples = c.subscribe(CLOCK, on_change=True, cycle_ms=CYCLE_MS)
            async with contextlib.aclosing(samples):
                times_s = [(await anext(samples)).value for _ in range(SAMPLES)]
    times_us = [round(t * 1e6) for t in times_s[1:]]
    assert times_us == sorted(set(times_us)), times_us
    assert [t for t in times_us if t % (CYCLE_MS * 1000)] == [], times_us
