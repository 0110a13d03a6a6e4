"""Issue 39 over the wire: ``G74`` with a sequence and P-AXIS-00277 per block, on a
real service whose configuration sets ``programs_need_referenced_axes`` (the default of
every axis' ``prog_move_requires_homing``)."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from cnc_objects.clients import ChannelError, Client
from cnc_objects.testing import ServiceProcess, run_program
from tests.support.service import home_channel, serving_config

AXES = ["ch1.ax1.homing_referenced_r", "ch1.ax2.homing_referenced_r",
        "ch1.ax3.homing_referenced_r"]


@pytest.fixture(scope="module")
def machine(tmp_path_factory: pytest.TempPathFactory) -> Iterator[ServiceProcess]:
    with serving_config(tmp_path_factory.mktemp("homing"),
                        "programs_need_referenced_axes = true\n") as service:
        yield service


def test_a_program_starts_and_stops_at_the_block_that_moves_an_unreferenced_axis(
        machine: ServiceProcess) -> None:
    with Client(machine.endpoint, timeout_s=30.0) as c:
        c.reset(1)
        c.upload("move.nc", b"N10 G01 X1 F600\nM30\n")
        with pytest.raises(ChannelError) as info:
            run_program(c, "move.nc", timeout_s=60)
        assert "error 50110: move.nc:1:1:" in str(info.value)
        assert c.read("ch1.mc_referencing_required_r") is True
        c.reset(1)
        # G74 Z1 X2 Y2 over MDI: Z first, then X and Y together; then the program runs
        home_channel(machine.endpoint, axes="Z1 X2 Y2")
        assert c.read_many(AXES) == dict.fromkeys(AXES, True)
        assert c.read("ch1.mc_referencing_required_r") is False
        run_program(c, "move.nc", timeout_s=60)
        assert c.read("ch1.ax1.command_position_acs") == 10_000  # 1 mm in 0.1 um
