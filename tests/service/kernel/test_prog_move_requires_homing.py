"""P-AXIS-00277 ``prog_move_requires_homing`` per axis (issue 39, departure 11): a
program starts whatever is referenced; only a block that moves an unreferenced axis
whose parameter is set is an error (50110, at that block, before any axis moves)."""

from __future__ import annotations

import copy
from collections.abc import Iterator

import pytest

from cnc_objects.protocol.values import ChannelState
from cnc_objects.service.config import build_config
from cnc_objects.service.machine_config import DEFAULT_MACHINE, MachineConfig
from tests.support.kernel import KernelHarness


def _x_needs_homing() -> MachineConfig:
    """The default machine with P-AXIS-00277 set on X of channel 1 only."""
    data = copy.deepcopy(DEFAULT_MACHINE)
    data["channels"][0]["axes"][0]["manual"] = {"prog_move_requires_homing": True}
    return build_config(data)


@pytest.fixture
def k() -> Iterator[KernelHarness]:
    with KernelHarness(config=_x_needs_homing()) as harness:
        yield harness


def test_a_program_that_moves_only_other_axes_runs(k: KernelHarness) -> None:
    run = k.run("N10 G01 Y5 Z-2 F600\nM30\n")
    assert run.channel.state == ChannelState.READY, run.channel.errors.entries
    assert run.positions_mm == pytest.approx((0.0, 5.0, -2.0))


def test_the_block_that_moves_the_unreferenced_axis_is_the_error(k: KernelHarness) -> None:
    run = k.run("N10 G01 Y5 F600\nN20 G01 X3 Y6\nM30\n", name="p.nc")
    assert run.channel.state == ChannelState.ERROR
    [error] = run.channel.errors.entries
    assert (error.id, error.file, error.line, error.column) == (50110, "p.nc", 2, 1)
    assert "axis X is not referenced" in error.text and "P-AXIS-00277" in error.text
    assert run.positions_mm == pytest.approx((0.0, 5.0, 0.0))  # N10 ran, X never moved


def test_g74_in_the_program_lets_the_blocks_after_it_move_the_axis(k: KernelHarness) -> None:
    run = k.run("N10 G74 X1\nN20 G01 X5 F600\nM30\n")
    assert run.channel.state == ChannelState.READY, run.channel.errors.entries
    assert run.positions_mm[0] == pytest.approx(5.0)
    assert run.channel.manual[0].referenced


def test_a_manual_block_moving_the_axis_is_refused_until_homed(k: KernelHarness) -> None:
    run = k.mdi("G01 X2 F600")
    assert run.channel.state == ChannelState.ERROR
    assert run.channel.errors.entries[-1].id == 50110
