"""A rotary axis over the wire (issue 39): configured as ``axis_type = "rotary"`` (or
``kenngr.achs_typ ACHSTYP_ROTATOR`` in an axis list), shown as such in
``ch<c>.ax<a>.axis_type`` (2), positioned in 0.0001 degree, and tracking the main axes:
the feed acts along X, Y, Z (ISG's default feed group), a block that turns C alone runs
at F degrees/min."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest

from cnc_objects.clients import Client
from cnc_objects.testing import run_program
from tests.support.service import RunningService, reset_client, serving, serving_config

MACHINE = """
[[physical_axes]]
number = 1
name = "X"
[[physical_axes]]
number = 2
name = "Y"
[[physical_axes]]
number = 3
name = "Z"
[[physical_axes]]
number = 4
name = "C"

[[channels]]
id = 1
name = "main"
[[channels.axes]]
name = "X"
logical_number = 1
[[channels.axes]]
name = "Y"
logical_number = 2
[[channels.axes]]
name = "Z"
logical_number = 3
[[channels.axes]]
name = "C"
logical_number = 4
axis_type = "rotary"
limits = {vel_max_mm_s = 360.0, sw_limit_min_mm = -3600.0, sw_limit_max_mm = 3600.0}
"""
TENTH_UM_PER_MM = 10_000  # and 0.0001 degree per degree


@pytest.fixture(scope="module")
def machine(tmp_path_factory: pytest.TempPathFactory) -> Iterator[RunningService]:
    work: Path = tmp_path_factory.mktemp("rotary")
    with serving_config(work, MACHINE) as service:
        yield service


@pytest.fixture
def client(machine: RunningService) -> Iterator[Client]:
    with reset_client(machine) as c:
        yield c


def test_the_axis_type_is_shown(client: Client) -> None:
    assert [client.read(f"ch1.ax{a}.axis_type") for a in (1, 2, 3, 4)] == [1, 1, 1, 2]


def _at_zero(client: Client) -> None:
    client.wait_mdi(client.mdi("G90 G00 X0 Y0 Z0 C0"), timeout_s=30)


def test_c_tracks_x_and_the_feed_acts_along_x(client: Client) -> None:
    _at_zero(client)
    client.upload("tracks.nc", b"G90 G01 X10 C90 F600\nM30\n")
    status = run_program(client, "tracks.nc")
    assert status.positions_mm["X"] == pytest.approx(10.0)
    assert status.positions_mm["C"] == pytest.approx(90.0)
    assert client.read("ch1.ax4.command_position_acs") == 90 * TENTH_UM_PER_MM
    # the path is the 10 mm of X, at 10 mm/s (plus reaching and leaving that speed)
    assert client.read("ch1.dist_prog_start") == pytest.approx(10 * TENTH_UM_PER_MM)
    assert client.read("ch1.program_time") == pytest.approx(1.0, abs=0.05)


def test_c_alone_turns_at_f_degrees_per_minute(client: Client) -> None:
    _at_zero(client)
    client.upload("turns.nc", b"G90 G01 C-45 F1800\nM30\n")
    run_program(client, "turns.nc")
    assert client.read("ch1.ax4.command_position_acs") == -45 * TENTH_UM_PER_MM
    assert client.read("ch1.dist_prog_start") == pytest.approx(45 * TENTH_UM_PER_MM)
    # 45 degrees at 30 degrees/s, plus reaching and leaving that speed
    assert client.read("ch1.program_time") == pytest.approx(1.5, abs=0.05)


def test_the_five_axis_machine_runs_rtcp_over_the_wire() -> None:
    with serving("--machine", "five-axis-ac") as service, \
            Client(service.endpoint, timeout_s=10) as c:
        assert [c.read(f"ch1.ax{a}.axis_name") for a in range(1, 6)] == list("XYZAC")
        assert [c.read(f"ch1.ax{a}.axis_type") for a in range(1, 6)] == [1, 1, 1, 2, 2]
        c.upload("tilt.nc", b"G90 G01 X10 Y0 Z50 A0 C0 F3000\n#TRAFO ON\n"
                 b"G01 C90 F600\nM30\n")
        status = run_program(c, "tilt.nc")
        # the tip stayed at the workpiece's (10, 0, 50) while the table turned 90: the
        # machine follows it to (0, 10, 50)
        assert [status.positions_mm[n] for n in "XYZAC"] == pytest.approx(
            [0.0, 10.0, 50.0, 0.0, 90.0])
        assert c.read("ch1.trafo_active_r") is True
        assert c.read("ch1.ax2.command_position_acs") == 10 * TENTH_UM_PER_MM
