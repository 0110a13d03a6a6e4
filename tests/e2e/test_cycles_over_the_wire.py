"""Cycles over the wire: the documentation's example programs run on the service, their
result files are downloaded from the store, the #HSC settings and #MSG texts are objects,
and a syntax check reports a call's parameter errors."""

from __future__ import annotations

from pathlib import Path

from cnc_objects.clients import Client
from cnc_objects.testing import run_program

EXAMPLES = Path(__file__).resolve().parents[2] / "docs" / "examples"


def _upload(api: Client, *paths: Path) -> None:
    for path in paths:
        api.upload(path.name, path.read_bytes())


def _run(api: Client, name: str) -> None:
    run_program(api, name, timeout_s=60)
    assert api.read("ch1.mc_error_count_r") == 0, api.read("ch1.mc_error_1_text_r")


def test_calculation_rotation_and_pattern_examples_run_on_the_service(cnc_client: Client) -> None:
    api = cnc_client
    cycles = EXAMPLES / "cycles"
    _upload(api, *sorted(cycles.iterdir()))
    _run(api, "calc-circle.nc")
    assert api.download_output("SysCalcCircleResult.txt").decode() == (
        "Center X = 0.000000\nCenter Y = 0.000000\nRadius = 1.000000\n"
        "Variance = 0.000000\n")
    _run(api, "calc-circle.nc")  # EXCLUSIVE: the second run replaces the file again
    assert api.download_output("SysCalcCircleResult.txt").decode().count("Radius") == 1
    _run(api, "rotate-to-plane.nc")
    result = api.download_output("SysPosRotationToPlaneResult.txt").decode().splitlines()
    assert result[2:6] == ["Origin = 140.000000, 0.000000, -80.000000",
                           "X axis = 0.000000, 1.000000, 0.000000",
                           "Y axis = -0.514496, 0.000000, 0.857493",
                           "Z axis = 0.857493, 0.000000, 0.514496"]
    # G01 X10 Y0 Z0 in the rotated system: the origin + 10 along its X axis (0, 1, 0)
    assert [api.read(f"ch1.ax{a}.command_position_acs") for a in (1, 2, 3)] == [
        1_400_000, 100_000, -800_000]
    _run(api, "pattern.nc")
    # last position (0, 100, 10), not rotated: the cycle's X10 then back to Z100
    assert [api.read(f"ch1.ax{a}.command_position_acs") for a in (1, 2, 3)] == [
        100_000, 1_000_000, 1_000_000]


def test_hsc_settings_example_shows_the_settings_and_messages(cnc_client: Client) -> None:
    api = cnc_client
    _upload(api, *sorted((EXAMPLES / "hsc").iterdir()))
    _run(api, "hsc-settings.nc")
    assert api.read("ch1.hsc_active_r") is True
    assert api.read("ch1.hsc_surface_r") is True
    assert abs(api.read("ch1.hsc_path_dev_r") - 0.01) < 1e-12  # hscs.finish.tolerance 100
    assert api.read("ch1.slope_type_r") == "HSC"
    assert api.read("ch1.acc_weight_r") == 80.0
    assert api.read("ch1.filter_active_r") is True
    api.upload("msg.nc", b'#MSG ["first"]\n#MSG ["part %d done", 7]\nM30\n')
    _run(api, "msg.nc")
    assert api.read("ch1.mc_message_count_r") == 2
    assert api.read("ch1.mc_message_1_text_r") == "part 7 done"
    assert api.read("ch1.mc_message_2_text_r") == "first"
    assert api.read("ch1.hsc_active_r") is False  # a program start resets the settings
    assert api.read("ch1.acc_weight_r") == 100.0


def test_syntax_check_reports_each_parameter_error_of_a_cycle_call(cnc_client: Client) -> None:
    api = cnc_client
    api.upload("bad.nc", b"L CYCLE [NAME=SysCalcCircle.ecy @P50=0 @P60=1 @P51=1 @P61=0 \\\n"
                         b"  @P52=2 @P62=\"x\" @P70=3]\n"
                         b"L CYCLE [NAME=SysHscSettings.ecy @P1=7]\nM30\n")
    result = api.syntax_check("bad.nc", timeout_s=60)
    found = [(e.id, e.line, e.column) for e in result.errors]
    assert found == [(20514, 2, 10), (20513, 2, 19), (20514, 3, 34)], result.errors
    assert api.read("ax1.command_position_acs") == 0
