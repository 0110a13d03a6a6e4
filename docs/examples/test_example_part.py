"""Integration tests of an NC program against a real cnc-service (docs/testing.md).

Copy this file and example-part.nc into your project's tests; with cnc-objects and
pytest installed, ``pytest`` runs them. No conftest.py is needed: the fixtures come from
the cnc-objects pytest plugin.
"""

from __future__ import annotations

import pytest

from cnc_objects.clients import ChannelError, Client
from cnc_objects.testing import run_program, wait_for

# Every test here gets a fresh service (virtual clock) with example-part.nc in its
# program store; the path is taken from this file's directory.
pytestmark = pytest.mark.cnc_service(programs=["example-part.nc"])

HOLD = 5  # ch1.mc_active_state_r while the channel is in feedhold


def test_the_part_runs_to_its_end(cnc_client: Client) -> None:
    status = run_program(cnc_client, "example-part.nc", timeout_s=60)
    assert (status.state, status.block_number) == ("READY", 90)
    assert status.positions_mm == {"X": 0.0, "Y": 0.0, "Z": 5.0}
    # Kernel time, not wall time: the same on every machine, for every run.
    assert status.program_time_s == pytest.approx(2.991, abs=0.01)


def test_half_the_feed_nearly_doubles_the_time(cnc_client: Client) -> None:
    full_s = run_program(cnc_client, "example-part.nc").program_time_s
    cnc_client.write("ch1.mc_command_feed_override_w", 500)  # 0.1 %: 50 %
    half_s = run_program(cnc_client, "example-part.nc").program_time_s
    assert 1.8 * full_s < half_s < 2.0 * full_s  # the rapid moves (G0) keep their speed


def test_a_bad_block_stops_the_channel_with_file_and_line(cnc_client: Client) -> None:
    cnc_client.upload("broken.nc", b"G1 X10 F600\nG1 Y10 Q7\nM30\n")
    with pytest.raises(ChannelError) as error:
        run_program(cnc_client, "broken.nc")
    assert "broken.nc:2:" in str(error.value)
    cnc_client.reset()


# Kernel time at the pace of the wall clock (--speed 1), so that the test can act while
# the part is machined; a marker on the test replaces the module's marker.
@pytest.mark.cnc_service(programs=["example-part.nc"], args=["--speed", "1"])
def test_feedhold_stops_the_path(cnc_client: Client) -> None:
    cnc_client.run_program("example-part.nc")  # starts it and returns
    wait_for(cnc_client, "ch1.actual_path_velocity", lambda v_um_s: v_um_s > 0)
    cnc_client.hold()
    wait_for(cnc_client, "ch1.actual_path_velocity", 0.0)
    assert cnc_client.read("ch1.mc_active_state_r") == HOLD
    cnc_client.reset()
