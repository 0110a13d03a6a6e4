"""A subscription without ``cycle_ms`` is checked every 10 ms of kernel time, not every
cycle (issue 36: one moving axis sent 926 samples/s); ``cycle_ms=0`` still asks for every
cycle."""

from __future__ import annotations

import contextlib

import pytest

from cnc_objects.clients import AsyncClient
from cnc_objects.testing import serving

SAMPLES = 12
DEFAULT_ON_CHANGE_CYCLE_MS = 10  # documented in the README, "From Python"
CLOCK = "cnc_kernel_time_r"  # s; changes every kernel cycle (1 ms)


async def _times_ms(endpoint: str, **options: int) -> list[int]:
    """Kernel times (ms) of the samples after the first (the current value)."""
    async with AsyncClient(endpoint) as c:
        samples = c.subscribe(CLOCK, **options)
        async with contextlib.aclosing(samples):
            times = [(await anext(samples)).value for _ in range(SAMPLES)]
    return [round(t * 1000) for t in times[1:]]


@pytest.fixture(scope="module")
def realtime_endpoint() -> str:  # type: ignore[misc]
    with serving("--clock", "realtime") as service:  # the ticker runs on its own
        yield service.endpoint


async def test_a_default_subscription_samples_every_10_ms(realtime_endpoint: str) -> None:
    """Checked on the 10 ms grid of kernel time (read at the newest cycle when the check
    runs): one sample per 10 ms window at most."""
    times_ms = await _times_ms(realtime_endpoint)
    windows = [t // DEFAULT_ON_CHANGE_CYCLE_MS for t in times_ms]
    assert len(set(windows)) == len(windows), times_ms


async def test_cycle_ms_0_still_samples_every_cycle(realtime_endpoint: str) -> None:
    times_ms = await _times_ms(realtime_endpoint, cycle_ms=0)
    windows = [t // DEFAULT_ON_CHANGE_CYCLE_MS for t in times_ms]
    assert len(set(windows)) < len(windows), times_ms
