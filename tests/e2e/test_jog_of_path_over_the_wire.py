"""Jog of path over the wire: the docs' CLI walkthrough, PLC symbols, parameter update,
and a machine configured from ISG parameter lists."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from cnc_objects.clients import AdsError, ChannelError, Client
from cnc_objects.protocol.constants import CncPort
from cnc_objects.testing import ServiceProcess, serving
from tests.support.cli import cnc, json_lines
from tests.support.entry_point import run_service

PARAMS = Path(__file__).parent.parent / "data" / "params"
SUSPEND = "gpCh[{}].bahn_mc_control.suspend_axis_output.command_w"


def read_mm(endpoint: str, *names: str) -> list[float]:
    result = cnc("--json", "read", *names, endpoint=endpoint)
    assert result.returncode == 0, result.stderr
    return [r["value"] for r in json_lines(result)]  # in mm, as cnc shows positions


def ok(endpoint: str, *args: str) -> None:
    result = cnc(*args, endpoint=endpoint)
    assert result.returncode == 0, (args, result.stdout, result.stderr)


def test_the_table_with_the_cli_only(cnc_service: ServiceProcess) -> None:
    """docs/jog-of-path.md, "Walkthrough": the same commands, the same numbers."""
    e = cnc_service.endpoint
    columns = ("ch1.ax1.command_position_acs", "ch2.ax1.command_position_acs",
               "ax1.command_position_acs", "ch1.ax1.position_offset",
               "ch2.ax1.position_offset")
    ok(e, "write", "ch1.mc_command_execution_mode_w", "0x80")
    ok(e, "write", "ch2.mc_command_execution_mode_w", "0x80")
    ok(e, "mdi", "--wait", "G01 G90 X50 F6000")
    assert read_mm(e, *columns) == [50, 0, 50, 0, 0]
    ok(e, "write", SUSPEND.format(0), "1")
    ok(e, "write", SUSPEND.format(1), "0")
    ok(e, "mdi", "-c", "2", "--wait", "G01 G90 X15 F6000")
    assert read_mm(e, *columns) == [50, 15, 15, 0, 0]
    ok(e, "write", SUSPEND.format(1), "1")
    ok(e, "write", SUSPEND.format(0), "0")
    ok(e, "mdi", "--wait", "X80")
    assert read_mm(e, *columns) == [80, 15, 45, 35, -30]
    ok(e, "write", SUSPEND.format(0), "1")
    ok(e, "write", SUSPEND.format(1), "0")
    ok(e, "mdi", "-c", "2", "--wait", "X0")
    assert read_mm(e, *columns) == [80, 0, 30, 50, -30]
    # PLC side: drive X (slot 0) is driven by axis 11 with offset -30 mm.
    plc = cnc("--json", "read", "gpAx[0].lr_state.position_offset_r",
              "gpAx[0].lr_state.link_to_ipo_r", "gpAx[3].ipo_state.link_to_lr",
              "gpAx[0].ipo_state.link_to_lr", endpoint=e)
    assert [r.get("raw", r["value"]) for r in json_lines(plc)] == [-300_000, 11, 1, 0]


@pytest.fixture(scope="module")
def machine():
    with serving() as service:
        yield service


def test_plc_symbols_live_on_port_851_and_refuse_bad_writes(machine) -> None:
    with Client(machine.endpoint, timeout_s=10) as c:
        [state] = c.browse("gpCh[1].bahn_mc_control.suspend_axis_output.state_r")
        assert (state.port, state.type, state.access) == (CncPort.PLC, "BOOLEAN", "r")
        assert c.read("gpCh[1].bahn_mc_control.suspend_axis_output.state_r") is True
        assert c.read("gpCh[1].bahn_mc_control.suspend_axis_output.enable_w") is True
        with pytest.raises(AdsError) as info:
            c.write("gpCh[1].bahn_mc_control.suspend_axis_output.state_r", False)
        assert info.value.code == 0x704
        # Channel 1 in error: suspending its output is refused until RESET.
        before = c.mdi("G01 X1 F6000 Q3")
        with pytest.raises(ChannelError):
            c.wait_mdi(before, timeout_s=10)
        assert c.read("ch1.mc_active_state_r") == 6  # ERROR
        with pytest.raises(AdsError) as info:
            c.write(SUSPEND.format(0), True)
        assert info.value.code == 0x707 and "RESET" in str(info.value)
        assert c.read(SUSPEND.format(0)) is False
        c.reset(1)
        c.write(SUSPEND.format(0), True)
        c.write(SUSPEND.format(0), False)


def test_master_update_does_not_reach_the_clone(machine) -> None:
    with Client(machine.endpoint, timeout_s=10) as c:
        assert c.read("ch2.ax2.vel_max") == c.read("ch1.ax2.vel_max") == 500.0
        c.write("axis_parameter_update_w", "kopf.achs_nr 2\ngetriebe[0].dynamik.vb_max 120000\n")
        assert c.read("ch1.ax2.vel_max") == 120.0
        assert c.read("ch2.ax2.vel_max") == 500.0
        with pytest.raises(AdsError) as info:
            c.write("axis_parameter_update_w", "kopf.achs_nr 12\nkopf.clone_of 3\n")
        assert info.value.code == 0x706 and "cannot change" in str(info.value)
        with pytest.raises(AdsError) as info:
            c.write("axis_parameter_update_w", "kopf.achs_nr 2\ngetriebe[0].dynamik.a_max x\n")
        assert info.value.code == 0x706 and "axis_parameter_update_w:2:" in str(info.value)
        assert c.read("ch1.ax2.acc_max") == 5000.0  # nothing changed


def test_machine_from_isg_parameter_lists(tmp_path) -> None:
    for name in ("axis-11.lis", "channel-2.lis"):
        shutil.copy(PARAMS / name, tmp_path / name)
    for number in (12, 13):  # the other two clones, written here: master = number - 10
        (tmp_path / f"axis-{number}.lis").write_text(
            f"kopf.achs_nr {number}\nkopf.clone_of {number - 10}  # takes link_to too\n"
        )
    config = tmp_path / "machine.toml"
    config.write_text(
        'axis_parameter_lists = ["axis-11.lis", "axis-12.lis", "axis-13.lis"]\n'
        '[[channels]]\nid = 1\nname = "main"\n'
        'axes = [{name = "X", logical_number = 1}, {name = "Y", logical_number = 2},'
        ' {name = "Z", logical_number = 3}]\n'
        '[[channels]]\nid = 2\nname = "jog"\nparameter_list = "channel-2.lis"\n'
        "suspend_output_at_start = true\n"
    )
    with serving("--config", str(config)) as service, \
            Client(service.endpoint, timeout_s=10) as c:
        values = c.read_many(["ch2.ax1.logical_axis_number", "ch2.ax1.axis_name",
                              "ch2.ax3.requested_link_to_physical_axis",
                              "ch2.mc_error_count_r", "ch2.mc_active_state_r",
                              "ch2.ax1.vel_max", "ch2.ax2.vel_max"])
        assert values == {"ch2.ax1.logical_axis_number": 11, "ch2.ax1.axis_name": "X",
                          "ch2.ax3.requested_link_to_physical_axis": 3,
                          "ch2.mc_error_count_r": 0, "ch2.mc_active_state_r": 1,
                          "ch2.ax1.vel_max": 250.0,  # axis-11.lis overrides it
                          "ch2.ax2.vel_max": 500.0}  # inherited from axis 2
    # A bad list refuses the start and names file and line.
    shutil.copy(PARAMS / "axis-bad.lis", tmp_path / "axis-11.lis")
    bad = run_service("--config", str(config))
    assert bad.returncode == 2, bad.stderr
    assert f"{tmp_path / 'axis-11.lis'}:" in bad.stderr


def test_clone_of_a_missing_master_shows_two_warnings(tmp_path) -> None:
    config = tmp_path / "machine.toml"
    config.write_text(
        '[[channels]]\nid = 1\nname = "main"\naxes = [{name = "X", logical_number = 1}]\n'
        '[[channels]]\nid = 2\nname = "jog"\n'
        'axes = [{name = "X", logical_number = 11, link_to = 1, clone_of = 99}]\n'
    )
    with serving("--config", str(config)) as service, \
            Client(service.endpoint, timeout_s=10) as c:
        lines = c.channel_errors(2)
        assert [line.split(":")[0] for line in lines] == ["warning 70172", "warning 50462"]
        assert "master axis 99" in lines[0]
        assert c.read("ch2.mc_error_1_warning_r") is True
        assert c.read("ch2.mc_active_state_r") != 6  # a warning does not stop it
