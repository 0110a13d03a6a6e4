"""The programmed feed acts along the main axes; other axes track them (ISG's default
feed group, tf5200_programming_manual/207471243.html #FGROUP and P-CHAN-00011).

A channel with X, Y, Z and a fourth axis U: ``G01 X30 U90 F1800`` moves the path 30 mm
at 30 mm/s, and U covers its 90 mm in the same time (90 mm/s). Before, the feed acted
along the distance over all four axes (94.9 mm), and the block took 3.2 s instead of
1 s. A block that moves U alone is measured along U.
"""

from __future__ import annotations

import copy
from collections.abc import Iterator

import pytest

from cnc_objects.service.config import build_config
from cnc_objects.service.kernel.channel_mode import ChannelState
from cnc_objects.service.machine_config import DEFAULT_MACHINE
from tests.support.kernel import KernelHarness, Run

ACC_MM_S2 = 5000.0  # the default axis acceleration
U_VEL_MAX_MM_S = 500.0  # the default axis velocity limit


@pytest.fixture
def four_axes() -> Iterator[KernelHarness]:
    data = copy.deepcopy(DEFAULT_MACHINE)
    data["physical_axes"].append({"number": 4, "name": "U"})
    data["channels"][0]["axes"].append({"name": "U", "logical_number": 4, "link_to": 4})
    with KernelHarness(config=build_config(data)) as harness:
        yield harness


def _ran(run: Run) -> Run:
    assert run.channel.state == ChannelState.READY, run.channel.errors.entries
    return run


def test_the_feed_acts_along_the_main_axes_and_u_tracks(four_axes: KernelHarness) -> None:
    run = _ran(four_axes.run("G01 X30 U90 F1800\nM30\n", record=True))
    assert run.positions_mm[:4] == pytest.approx((30.0, 0.0, 0.0, 90.0))
    assert max(s.path_velocity_mm_s for s in run.samples) == pytest.approx(30.0)
    # a trapezoid: 30 mm at 30 mm/s, and 30 / a to reach and to leave that speed, where
    # U's share (3 mm per mm of path) limits the path acceleration to 5000 / 3
    expected_s = 30.0 / 30.0 + 30.0 / (ACC_MM_S2 / 3.0)
    assert run.channel.path.program_time_s == pytest.approx(expected_s, abs=0.003)
    # the path distance counts the main axes only (0.1 um)
    assert run.channel.path.dist_prog_start_01um == pytest.approx(300_000.0)
    # U moves three times as far as X in every cycle: it arrives with X
    for sample in run.samples:
        x, u = sample.positions_mm[0], sample.positions_mm[3]
        assert u == pytest.approx(3.0 * x, abs=1e-9)


def test_a_tracking_axis_alone_is_measured_along_itself(four_axes: KernelHarness) -> None:
    run = _ran(four_axes.run("G01 U90 F1800\nM30\n", record=True))
    assert max(s.path_velocity_mm_s for s in run.samples) == pytest.approx(30.0)
    assert run.channel.path.program_time_s == pytest.approx(
        90.0 / 30.0 + 30.0 / ACC_MM_S2, abs=0.003)


def test_a_tracking_axis_still_limits_the_path_speed(four_axes: KernelHarness) -> None:
    # U moves 4 mm per mm of path: its 500 mm/s allow the path 125 mm/s
    run = _ran(four_axes.run("G01 X100 U400 F60000\nM30\n", record=True))
    assert max(s.path_velocity_mm_s for s in run.samples) == pytest.approx(
        U_VEL_MAX_MM_S / 4.0)
