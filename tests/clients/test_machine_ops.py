"""The client's machine functions in engineering units (issue 36): ``read``, ``write``,
``read_many`` and ``subscribe`` with ``units=True``; jog, home, tools, zero offsets and
the spindle as client methods, against a real service (virtual clock), with the blocking
``Client`` and the ``AsyncClient``."""

from __future__ import annotations

import contextlib

import pytest

from cnc_objects.clients import AsyncClient, Client, ClientValueError
from cnc_objects.testing import ServiceProcess

OVERRIDE_R, OVERRIDE_W = "ch1.mc_active_feed_override_r", "ch1.mc_command_feed_override_w"
POSITION = "ch1.ax1.command_position_acs"
TIMEOUT_S = 30.0


def test_read_and_write_in_engineering_units(cnc_client: Client) -> None:
    c = cnc_client
    assert c.read(OVERRIDE_R) == 1000  # 0.1 %: the object's own unit
    assert c.read(OVERRIDE_R, units=True) == 100.0
    assert c.describe(OVERRIDE_R).engineering_unit == "%"
    c.write(OVERRIDE_W, 62.5, units=True)
    assert c.read(OVERRIDE_R) == 625
    assert c.read_many([OVERRIDE_R, POSITION], units=True) == {OVERRIDE_R: 62.5, POSITION: 0.0}
    assert c.describe(POSITION).engineering_unit == "mm"
    with pytest.raises(ClientValueError, match="out of range"):
        c.write(OVERRIDE_W, 1e9, units=True)
    with pytest.raises(ClientValueError, match="takes a number"):
        c.write(OVERRIDE_W, "50", units=True)
    assert c.read(OVERRIDE_R) == 625  # nothing was sent


async def test_subscribe_in_engineering_units(cnc_service: ServiceProcess) -> None:
    async with AsyncClient(cnc_service.endpoint) as c:
        samples = c.subscribe(OVERRIDE_R, units=True)
        async with contextlib.aclosing(samples):
            assert (await anext(samples)).value == 100.0
            await c.write(OVERRIDE_W, 250)
            assert (await anext(samples)).value == 25.0


def test_jog_and_home_in_mm(cnc_client: Client) -> None:
    c = cnc_client
    assert c.axis_names() == ["X", "Y", "Z"]
    state = c.jog("X", "+", increment_mm=0.5, timeout_s=TIMEOUT_S)
    assert (state.axis, state.index, state.position_mm, state.moving) == ("X", 1, 0.5, False)
    assert c.read(POSITION) == 5000  # 0.1 um
    assert c.read("ch1.mc_active_mode_r") == 4  # MANUAL, selected by the jog
    assert c.jog(1, "-", timeout_s=TIMEOUT_S).position_mm == -0.5  # default: 1 mm
    assert c.jog("y", -1, handwheel_pulses=10, timeout_s=TIMEOUT_S).position_mm < 0
    [x, z] = c.home(["X", "Z"], timeout_s=TIMEOUT_S)
    assert (x.axis, x.referenced, z.axis, z.referenced) == ("X", True, "Z", True)
    with pytest.raises(ClientValueError, match="no axis 'Q'.*X, Y, Z"):
        c.jog("Q", "+")
    with pytest.raises(ClientValueError, match="choose one"):
        c.jog("X", "+", increment_mm=1.0, continuous=True)


def test_continuous_jog_until_stopped(cnc_client: Client) -> None:
    c = cnc_client
    c.jog("Z", "+", continuous=True)  # returns at once, the key left pressed
    assert c.read("ch1.ax3.manual_jog_plus_w")
    stopped = c.jog_stop("Z", timeout_s=TIMEOUT_S)  # waits until it stands
    assert not c.read("ch1.ax3.manual_jog_plus_w")
    assert not stopped.moving and stopped.position_mm > 0


def test_tools_and_zero_offsets_in_mm(cnc_client: Client) -> None:
    c = cnc_client
    c.set_tool(3, radius_mm=4.25, length_mm=50.0)
    row = c.tools()[2]
    assert (row.wz, row.valid, row.radius_mm, row.length_mm) == (3, True, 4.25, 50.0)
    assert c.read("ch1.wz[3].radius") == 42500  # 0.1 um
    c.set_tool(3, valid=False)
    assert not c.tools()[2].valid
    c.set_zero_offset("G54", {"X": 10.0, "y": -5.5})
    table = c.zero_offsets()
    assert table.groups[1]["X"] == 10.0 and table.groups[1]["Y"] == -5.5
    assert table.axes == ("X", "Y", "Z") and table.positions_mm["X"] == {"acs": 0.0, "pcs": 0.0}
    with pytest.raises(ClientValueError, match="G54..G59"):
        c.set_zero_offset("G99", {"X": 1.0})
    with pytest.raises(ClientValueError, match="has the axes"):
        c.set_zero_offset(1, {"Q": 1.0})
    assert c.active_tool().d == 0


def test_spindle_in_rpm_and_percent(cnc_client: Client) -> None:
    c = cnc_client
    c.set_spindle_override(80.0)
    assert c.read("ch1.mc_spindle_override_w") == 800
    c.start_spindle(1200, timeout_s=TIMEOUT_S)
    s = c.spindle()
    assert (s.mode, s.programmed_rpm, s.override_pct) == ("M3", 1200.0, 80.0)
    assert s.commanded_rpm == pytest.approx(960.0)
    c.stop_spindle(timeout_s=TIMEOUT_S)
    assert c.spindle().mode == "M5"
