"""Manual mode and homing over the wire, as an HMI and a PLC drive them: the objects,
the HLI status symbols on port 851, the ADS errors of refused writes, and the CLI."""

from __future__ import annotations

import time

import pytest

from cnc_objects.clients import AdsError, Client
from cnc_objects.protocol.constants import CncPort
from cnc_objects.testing import ServiceProcess, serving
from tests.support.cli import cnc, json_lines

HB = "gpCh[0].bahn_state.coord_r[{}].hb_display_r.{}"


@pytest.fixture(scope="module")
def machine():
    with serving() as service:
        yield service


def wait_standstill(c: Client, prefix: str, timeout_s: float = 30.0) -> None:
    """Poll the axis's manual_moving_r until FALSE (the service runs on the virtual
    clock, so the motion takes little wall time)."""
    deadline = time.monotonic() + timeout_s
    while c.read(f"{prefix}.manual_moving_r"):
        assert time.monotonic() < deadline, f"{prefix} still moves"
        time.sleep(0.01)


def test_the_hli_status_symbols_live_on_port_851(machine: ServiceProcess) -> None:
    with Client(machine.endpoint, timeout_s=10) as c:
        [info] = c.browse(HB.format(2, "operation_mode"))
        assert (info.port, info.type, info.access) == (CncPort.PLC, "UNS16", "r")
        assert info.enum == {0: "NONE", 1: "HANDWHEEL", 2: "CONTINUOUS", 3: "INCREMENTAL"}
        c.write("ch1.mc_command_reset_w", True)
        c.write("ch1.mc_command_mode_w", 4)
        c.write("ch1.ax3.manual_operation_mode_w", 1)
        c.write("ch1.ax3.manual_hr_aufloesung_w", 50)
        values = c.read_many([HB.format(2, f) for f in (
            "state", "operation_mode", "control_element", "hr_aufloesung", "tipp_geschw")])
        assert list(values.values()) == [2, 1, 1, 50, 16_666]  # ISG's default jog speed
        with pytest.raises(AdsError) as info_error:
            c.write(HB.format(2, "state"), 1)
        assert info_error.value.code == 0x704


def test_jog_by_objects_and_the_errors_of_refused_writes(machine: ServiceProcess) -> None:
    with Client(machine.endpoint, timeout_s=10) as c:
        c.write("ch1.mc_command_reset_w", True)
        c.write("ch1.mc_command_mode_w", 2)  # AUTOMATIC: jog is refused
        c.write("ch1.ax1.manual_operation_mode_w", 3)
        with pytest.raises(AdsError) as refused:
            c.write("ch1.ax1.manual_jog_plus_w", True)
        assert refused.value.code == 0x707 and "MANUAL" in str(refused.value)
        c.write("ch1.mc_command_mode_w", 4)
        start = c.read("ch1.ax1.command_position_acs")
        with pytest.raises(AdsError) as out_of_range:
            c.write("ch1.ax1.manual_increment_w", 100_001)
        assert out_of_range.value.code == 0x706 and "0.1 um .. 10 mm" in str(out_of_range.value)
        c.write("ch1.ax1.manual_increment_w", 25_000)
        c.write("ch1.ax1.manual_jog_plus_w", True)
        c.write("ch1.ax1.manual_jog_plus_w", False)
        wait_standstill(c, "ch1.ax1")
        assert c.read("ch1.ax1.command_position_acs") == start + 25_000
        assert c.read("ax1.actual_position_acs") == start + 25_000  # the drive followed
        with pytest.raises(AdsError) as bad_mode:
            c.write("ch1.ax1.manual_operation_mode_w", 9)
        assert bad_mode.value.code == 0x706


def test_handwheel_counter_written_by_the_plc(machine: ServiceProcess) -> None:
    with Client(machine.endpoint, timeout_s=10) as c:
        c.write("ch1.mc_command_reset_w", True)
        c.write("ch1.mc_command_mode_w", 4)
        c.write("ch1.ax2.manual_operation_mode_w", 1)
        c.write("ch1.ax2.manual_hr_aufloesung_w", 100)  # 10 um per pulse
        start = c.read("ch1.ax2.command_position_acs")
        counter = c.read("ch1.ax2.manual_handwheel_counter_w")
        for step in (3, 7, 12):  # a PLC writes its counter as the wheel turns
            c.write("ch1.ax2.manual_handwheel_counter_w", counter + step)
        wait_standstill(c, "ch1.ax2")
        assert c.read("ch1.ax2.command_position_acs") == start + 12 * 100


def test_cnc_jog_and_cnc_home(machine: ServiceProcess) -> None:
    e = machine.endpoint
    assert cnc("reset", endpoint=e).returncode == 0
    # homed: from then on the software limits are monitored (P-AXIS-00705)
    result = cnc("--json", "home", "X", "Y", "Z", endpoint=e)
    assert result.returncode == 0, result.stderr
    records = json_lines(result)
    assert [(r["axis"], r["position_mm"], r["referenced"]) for r in records] == [
        ("X", 0.0, True), ("Y", 0.0, True), ("Z", 0.0, True)]
    result = cnc("--json", "jog", "X", "+", "--increment", "2.5", endpoint=e)
    assert result.returncode == 0, result.stderr
    [record] = json_lines(result)
    assert record["position_mm"] == 2.5 and not record["moving"]
    result = cnc("jog", "1", "-", "--handwheel", "40", endpoint=e)  # 40 x 1 um = 0.04 mm
    assert result.returncode == 0, result.stderr
    assert "axis X stands at 2.4600 mm" in result.stdout
    # a continuous jog holds its key (renewed: the service's dead-man) while it runs to
    # the software limit (+1000 mm) and stops there; a further increment toward it is
    # cut at the limit: a warning, exit 0
    result = cnc("--json", "jog", "Z", "+", "--continuous", "--rapid", endpoint=e)
    assert result.returncode == 0, result.stderr
    [record] = json_lines(result)
    assert record["position_mm"] == 1000.0 and not record["moving"] and record["limit_warning"]
    with Client(e, timeout_s=10) as c:
        assert c.read("ch1.ax3.manual_jog_plus_w") is False  # released as it ended
    result = cnc("--json", "jog", "Z", "+", "--increment", "0.5", endpoint=e)
    assert result.returncode == 0, result.stderr
    assert json_lines(result)[0]["position_mm"] == 1000.0
    assert "warning: axis Z stopped at its software limit" in result.stderr
    assert cnc("jog", "Z", "--stop", endpoint=e).returncode == 0
    bad = cnc("jog", "X", "+", "--increment", "11", endpoint=e)
    assert bad.returncode == 1 and "0.1 um .. 10 mm" in bad.stderr
    unknown = cnc("jog", "Q", "+", endpoint=e)
    assert unknown.returncode == 2 and "no axis 'Q'" in unknown.stderr


def test_cnc_jog_is_refused_while_the_channel_is_in_error(machine: ServiceProcess) -> None:
    e = machine.endpoint
    with Client(e, timeout_s=10) as c:
        c.write("ch1.mc_command_reset_w", True)
        c.write("ch1.mc_command_mode_w", 4)
        c.write("ch1.ax1.manual_operation_mode_w", 2)
        c.write("ch1.ax1.manual_jog_minus_w", True)
        c.write("ch1.mc_command_hold_w", True)
        wait_standstill(c, "ch1.ax1")
        assert c.read("ch1.mc_active_state_r") == 5  # HOLD
    held = cnc("jog", "X", "+", endpoint=e)
    assert held.returncode == 1 and "held" in held.stderr
    assert cnc("reset", endpoint=e).returncode == 0
