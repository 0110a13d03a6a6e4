"""What a value means and when it was produced, over the wire: value names in browse
replies, and notification timestamps in wall-clock time while virtual time runs ahead."""

from __future__ import annotations

import asyncio
import contextlib
from datetime import UTC, datetime, timedelta

from cnc_objects.clients import AsyncClient, Sample
from cnc_objects.protocol.values import ChannelMode, ChannelState, value_names
from tests.support.service import RunningService

# 100 blocks of 1 mm at 1 mm/min: 100 min of kernel time; the virtual clock runs it many
# times faster than real time (the event-speed clock a 1 min block in a few ms), so
# kernel time soon runs ahead of the wall clock.
SLOW_PROGRAM = "\n".join(
    ["N5 G90 G17", *(f"N{10 * k} G1 X{k} F1" for k in range(1, 101)), "N3000 M30", ""]
).encode()
SAMPLES_MIN = 50  # and at least this many samples of kernel time
SHARED_MIN = 10  # tick samples of cycles that kernel time was sampled at too
AHEAD_S = 2.0  # collect samples until kernel time is this far ahead of the wall clock
LATENCY_MAX = timedelta(seconds=1)  # from the cycle's end to the client, on a busy machine
CYCLE_S = 0.001  # the default configuration's cycle time


async def test_browse_names_the_values_of_enumeration_objects(endpoint: str) -> None:
    async with AsyncClient(endpoint) as c:
        found = {o.name: o for o in await c.browse("ch1.*")}
        assert found["ch1.mc_active_state_r"].enum == value_names(ChannelState)
        assert found["ch1.mc_active_state_r"].enum[3] == "READY"
        assert found["ch1.mc_command_mode_w"].enum == value_names(ChannelMode)
        assert found["ch1.ax2.link_state"].enum == {0: "LINKED", 1: "REQUESTED", 2: "WAITING_ACK"}
        # Not enumerations: a bit set, a counter, a position.
        for name in ("ch1.mc_active_execution_mode_r", "ch1.mc_error_count_r",
                     "ch1.ax1.command_position_acs"):
            assert found[name].enum == {}
        # What the client says about one object by name comes from the same rows.
        assert (await c.describe("CH1.MC_ACTIVE_MODE_R")).enum[2] == "AUTOMATIC"
        state = await c.read("ch1.mc_active_state_r")
        assert found["ch1.mc_active_state_r"].enum[state] == ChannelState(state).name


async def _collect(
    samples, into: list[tuple[Sample, datetime]], done: asyncio.Event
) -> None:
    async with contextlib.aclosing(samples):
        async for sample in samples:
            into.append((sample, datetime.now(UTC)))
            if done.is_set():
                return


async def test_sample_timestamps_are_the_wall_clock_time_of_their_cycle(
    service: RunningService,
) -> None:
    """Virtual time runs a program far ahead of the wall clock; the samples still carry
    the wall-clock time of the cycle that produced them: never ahead of their receipt,
    at most a moment behind, non-decreasing, and shared by samples of the same cycle."""
    async with AsyncClient(service.endpoint) as c:
        await c.upload("slow.nc", SLOW_PROGRAM)
        started = datetime.now(UTC)
        await c.run_program("slow.nc")
        times: list[tuple[Sample, datetime]] = []
        ticks: list[tuple[Sample, datetime]] = []
        done = asyncio.Event()
        async with asyncio.timeout(60):
            async with asyncio.TaskGroup() as tasks:
                tasks.create_task(_collect(c.subscribe("cnc_tick_counter_r"), ticks, done))
                # On change, checked every cycle: kernel time changes every cycle.
                async with contextlib.aclosing(c.subscribe("cnc_kernel_time_r")) as samples:
                    cycles: set[int] = set()  # of the kernel time samples
                    async for sample in samples:
                        times.append((sample, datetime.now(UTC)))
                        cycles.add(round(sample.value / CYCLE_S))
                        wall_s = (datetime.now(UTC) - started).total_seconds()
                        # until kernel time is well ahead of the wall clock, and (however
                        # busy the machine) ten tick samples fell on cycles sampled here
                        shared = sum(1 for s, _ in ticks if s.value in cycles)
                        if (sample.value - times[0][0].value > wall_s + AHEAD_S
                                and len(times) >= SAMPLES_MIN and shared >= SHARED_MIN):
                            break
                done.set()
        assert await c.read("ch1.mc_active_state_r") == ChannelState.ACTIVE  # still running

    for received in (times, ticks):
        stamps = [sample.timestamp for sample, _ in received]
        assert stamps == sorted(stamps)  # non-decreasing
        for sample, at in received:
            assert timedelta(0) <= at - sample.timestamp < LATENCY_MAX, (sample, at)
    # Samples of the same cycle (kernel time = ticks x cycle time) share their stamp.
    by_cycle = {round(s.value / CYCLE_S): s.timestamp for s, _ in times}
    same_cycle = [(by_cycle[s.value], s.timestamp) for s, _ in ticks if s.value in by_cycle]
    assert len(same_cycle) >= SHARED_MIN
    assert all(a == b for a, b in same_cycle)
