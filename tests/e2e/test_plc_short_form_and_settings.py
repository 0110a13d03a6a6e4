"""``[plc] acknowledges`` (the short form for a real PLC), the settings objects and the
referenced state, with a real service started on a configuration file.

The file holds only the short form and one machine key: the machine is the default one
(channels, axes) plus the acknowledged functions; M8 then waits for the PLC's
acknowledge over the wire while M7, not listed, is acknowledged by the embedded PLC.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest

from cnc_objects.clients import Client
from cnc_objects.protocol.wait_reasons import WaitReason
from cnc_objects.service.config import ConfigError, build_config, load_config
from cnc_objects.testing import ServiceProcess, start_service, wait_for

SHORT_FORM = """\
programs_need_referenced_axes = true

[plc]
acknowledges = ["M6", "M8", "m9"]
"""
UNITS = 16


def test_the_short_form_gives_the_default_machine_plus_the_acknowledged_functions(
        tmp_path: Path) -> None:
    path = tmp_path / "plc.toml"
    path.write_text(SHORT_FORM)
    config, default = load_config(path), build_config()
    assert config.channels == default.channels  # no channels array restated
    assert config.physical_axes == default.physical_axes
    assert config.plc.acknowledges == ("M6", "M8", "M9")
    assert config.plc.numbers("M") == {6, 8, 9} and config.plc.numbers("H") == frozenset()
    assert default.plc.acknowledges == ()


@pytest.mark.parametrize("entry", ["X8", "M", "8", "M-1", "MB"])
def test_a_wrong_acknowledged_function_is_refused_naming_the_key(
        tmp_path: Path, entry: str) -> None:
    path = tmp_path / "bad.toml"
    path.write_text(f'[plc]\nacknowledges = ["{entry}"]\n')
    with pytest.raises(ConfigError, match=r"plc\.acknowledges"):
        load_config(path)


@pytest.fixture(scope="module")
def service(tmp_path_factory: pytest.TempPathFactory) -> Iterator[ServiceProcess]:
    path = tmp_path_factory.mktemp("plc") / "plc.toml"
    path.write_text(SHORT_FORM)
    svc = start_service("--config", str(path))
    try:
        yield svc
    finally:
        svc.stop()


def test_settings_read_back_as_objects(service: ServiceProcess) -> None:
    with Client(service.endpoint) as c:
        got = c.read_many(["cnc_plc_acknowledges_r", "cnc_programs_need_referenced_axes_r",
                           "cnc_tool_change_time_r", "ch1.mc_feed_override_max_r",
                           "ch1.mc_plc_auto_acknowledge_r", "ch1.mc_g00_override_mode_r"])
    assert got == {"cnc_plc_acknowledges_r": "M6 M8 M9",
                   "cnc_programs_need_referenced_axes_r": True,
                   "cnc_tool_change_time_r": 0.0, "ch1.mc_feed_override_max_r": 1000,
                   "ch1.mc_plc_auto_acknowledge_r": True, "ch1.mc_g00_override_mode_r": 2}


def _unit_of(c: Client, m: int) -> int | None:
    names = [f"gpCh[0].techno_unit_std_sync[{k}].attribut_r.nr" for k in range(UNITS)]
    got = c.read_many(names)
    listed = [k for k, name in enumerate(names) if got[name] == m]
    return listed[-1] if listed else None


def test_referencing_then_the_plc_acknowledges_m8_and_not_m7(service: ServiceProcess) -> None:
    with Client(service.endpoint, timeout_s=30) as c:
        # referencing required: START is refused until every axis is homed
        assert c.read("ch1.mc_all_axes_referenced_r") is False
        assert c.read("ch1.mc_referencing_required_r") is True
        c.wait_mdi(c.mdi("G74 X1"), timeout_s=30)
        assert c.read("ch1.mc_all_axes_referenced_r") is False  # Y and Z are not
        assert c.read("ch1.mc_referencing_required_r") is True
        c.wait_mdi(c.mdi("G74 Y1 Z1"), timeout_s=30)
        assert c.read("ch1.mc_all_axes_referenced_r") is True
        assert c.read("ch1.mc_referencing_required_r") is False
        c.upload("coolant.nc", b"M7\nG01 X1 F6000\nM8\nG01 X2\nM30\n")
        c.run_program("coolant.nc")
        # M7 is the embedded PLC's; M8 waits for the real PLC's acknowledge
        wait_for(c, "gpCh[0].used_units_std_sync_r", 1, timeout_s=30)
        wait_for(c, "ch1.mc_wait_reason_r", WaitReason.PLC_ACKNOWLEDGE, timeout_s=30)
        unit = _unit_of(c, 8)
        assert unit is not None
        assert c.read(f"gpCh[0].techno_unit_std_sync[{unit}].state_r") is True
        assert c.read("ch1.ax1.command_position_acs") == 1 * 10_000  # stands after X1
        m7 = _unit_of(c, 7)
        assert m7 is not None
        assert c.read(f"gpCh[0].techno_unit_std_sync[{m7}].state_r") is False
        c.write(f"gpCh[0].techno_unit_std_sync[{unit}].command_w", True)
        c.wait_program(1, 30)
        assert c.read("ch1.ax1.command_position_acs") == 2 * 10_000
        assert c.read("ch1.mc_coolant_state_r") == 3  # M7 and M8
