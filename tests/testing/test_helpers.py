"""The test helpers of ``cnc_objects.testing``: run a program to its end, wait for a value."""

from __future__ import annotations

import time
from pathlib import Path

import pytest

from cnc_objects.clients import AdsTimeoutError, AsyncClient, ChannelError, Client
from cnc_objects.testing import run_program, run_program_async, wait_for, wait_for_async

DATA = Path(__file__).parent / "data"
HOLD = 5  # ch1.mc_active_state_r in feedhold
# 30 min of kernel time: under the event-speed virtual clock a run of 30 s would be over
# (in a few ms of wall time) before a wait that subscribes after the start has begun
LONG = b"G1 F600\n" + b"X300\nX0\n" * 30 + b"M30\n"


def test_run_program_runs_to_the_end_and_returns_the_status(cnc_client: Client) -> None:
    status = run_program(cnc_client, DATA / "short.nc")  # a local file: uploaded first
    assert "short.nc" in [p.name for p in cnc_client.programs()]
    assert (status.program, status.state, status.block_number) == ("short.nc", "READY", 20)
    assert status.positions_mm == {"X": 10.0, "Y": 5.0, "Z": 0.0}
    cnc_client.upload("home.nc", b"G0 X0 Y0\nM30\n")
    home = run_program(cnc_client, "home.nc", channel=1)  # by its name in the store
    assert (home.program, home.positions_mm) == ("home.nc", {"X": 0.0, "Y": 0.0, "Z": 0.0})


def test_run_program_raises_the_channels_error(cnc_client: Client) -> None:
    cnc_client.upload("bad.nc", b"G1 X10 F600\nG1 Y10 Q7\nM30\n")
    with pytest.raises(ChannelError) as error:
        run_program(cnc_client, "bad.nc")
    assert "bad.nc:2:" in str(error.value)


@pytest.mark.cnc_service(args=["--speed", "1"])
def test_run_program_that_does_not_end_in_time_is_reset(cnc_client: Client) -> None:
    cnc_client.upload("long.nc", LONG)
    with pytest.raises(AdsTimeoutError, match="still ACTIVE after 0.3 s"):
        run_program(cnc_client, "long.nc", timeout_s=0.3)
    assert cnc_client.status().state == "READY"  # stopped: it cannot disturb a next test


async def test_run_program_async(cnc_async_client: AsyncClient) -> None:
    status = await run_program_async(cnc_async_client, DATA / "short.nc")
    assert status.positions_mm["X"] == 10.0


def test_wait_for_a_value_a_predicate_and_approx(cnc_client: Client) -> None:
    assert wait_for(cnc_client, "ch1.mc_active_feed_override_r", 1000) == 1000  # current
    cnc_client.write("ch1.mc_command_feed_override_w", 333)
    assert wait_for(cnc_client, "ch1.mc_active_feed_override_r", lambda v: v < 500) == 333
    cnc_client.upload("long.nc", LONG)
    cnc_client.run_program("long.nc")
    # F600 at 33.3 %: 3.33 mm/s, reached after the ramp (the value is a float, in um/s)
    assert wait_for(cnc_client, "ch1.actual_path_velocity",
                    pytest.approx(3330.0, rel=1e-3)) == pytest.approx(3330.0, rel=1e-3)
    cnc_client.reset()


def test_wait_for_names_the_last_values_when_it_times_out(cnc_client: Client) -> None:
    started = time.monotonic()
    with pytest.raises(AdsTimeoutError) as error:
        wait_for(cnc_client, "ch1.mc_active_feed_override_r", 7, timeout_s=0.3)
    assert time.monotonic() - started < 5
    assert str(error.value).endswith(
        "ch1.mc_active_feed_override_r did not become 7 within 0.3 s; last values: 1000")
    with pytest.raises(AdsTimeoutError, match=r"did not satisfy <lambda> within 0.3 s"):
        wait_for(cnc_client, "ch1.mc_active_feed_override_r", lambda v: v < 0, timeout_s=0.3)


@pytest.mark.cnc_service(args=["--speed", "1"])
async def test_wait_for_async_sees_the_hold(cnc_async_client: AsyncClient) -> None:
    await cnc_async_client.upload("long.nc", LONG)
    await cnc_async_client.run_program("long.nc")
    await wait_for_async(cnc_async_client, "ch1.actual_path_velocity", lambda v: v > 0)
    await cnc_async_client.hold()
    assert await wait_for_async(cnc_async_client, "ch1.actual_path_velocity", 0.0) == 0.0
    assert await cnc_async_client.read("ch1.mc_active_state_r") == HOLD
    await cnc_async_client.reset()


async def test_the_blocking_helpers_refuse_an_async_client_and_a_running_loop(
    cnc_async_client: AsyncClient, cnc_service
) -> None:
    with pytest.raises(TypeError, match=r"await run_program_async\(...\)"):
        run_program(cnc_async_client, "x.nc")  # type: ignore[arg-type]
    with Client(cnc_service.endpoint) as blocking:
        with pytest.raises(RuntimeError, match=r"await wait_for_async\(...\)"):
            wait_for(blocking, "ch1.mc_active_state_r", 1)
