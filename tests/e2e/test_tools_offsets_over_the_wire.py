"""Tools and work offsets driven as an HMI drives them: the tool list and the zero offset
table written by objects, T/D/M6 and G53..G59/G159 in NC, the active values and the
positions in machine and workpiece coordinates read back (real service, virtual clock).
"""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from cnc_objects.clients import AdsError, ChannelError, Client
from cnc_objects.testing import ServiceProcess, run_program, wait_for
from tests.support.service import reset_client, serving_config

INCR = 10_000  # 0.1 um per mm


@pytest.fixture(scope="module")
def machine(tmp_path_factory) -> Iterator[ServiceProcess]:
    """One service with a tool change time of 2.5 s (a machine parameter)."""
    with serving_config(tmp_path_factory.mktemp("tools"), "tool_change_time_s = 2.5\n") as service:
        yield service


@pytest.fixture
def c(machine: ServiceProcess) -> Iterator[Client]:
    with reset_client(machine) as client:
        yield client


def run(c: Client, text: str, name: str = "tools.nc"):
    c.upload(name, text.encode())
    return run_program(c, name, timeout_s=60)


def errors(c: Client) -> list[str]:
    return c.channel_errors(1)


def test_the_configured_tool_list_is_readable_by_objects(c) -> None:
    values = c.read_many(["ch1.mc_tool_list_size_r", "ch1.wz[2].valid", "ch1.wz[2].radius",
                          "ch1.wz[2].laenge", "ch1.wz[4].valid"])
    assert values == {"ch1.mc_tool_list_size_r": 32, "ch1.wz[2].valid": True,
                      "ch1.wz[2].radius": 2.5 * INCR, "ch1.wz[2].laenge": 0.0,
                      "ch1.wz[4].valid": False}


def test_tool_select_change_and_length_compensation(c) -> None:
    c.write("ch1.wz[5].radius", 3.0 * INCR)
    c.write("ch1.wz[5].laenge", 100.0 * INCR)
    assert c.read("ch1.wz[5].valid") is False  # data alone does not make a tool
    c.write("ch1.wz[5].valid", True)
    status = run(c, "G0 X0 Y0 Z0\nT5 M6\nD5\nG0 Z20\nM30\n")
    assert status.state == "READY", errors(c)
    values = c.read_many([
        "ch1.mc_selected_tool_r", "ch1.mc_active_tool_r", "ch1.mc_active_tool_offset_r",
        "ch1.mc_active_tool_radius_r", "ch1.mc_active_tool_length_r", "ch1.actual_tool_radius",
        "ch1.ax3.command_position_acs", "ch1.ax3.command_position_pcs", "ch1.program_time",
    ])
    assert values["ch1.mc_selected_tool_r"] == 5
    assert values["ch1.mc_active_tool_r"] == 5
    assert values["ch1.mc_active_tool_offset_r"] == 5
    assert values["ch1.mc_active_tool_radius_r"] == values["ch1.actual_tool_radius"] == 3.0 * INCR
    assert values["ch1.mc_active_tool_length_r"] == 100.0 * INCR
    # Z20 is the tool tip: the machine axis goes to 20 + the tool length
    assert values["ch1.ax3.command_position_acs"] == 120 * INCR
    assert values["ch1.ax3.command_position_pcs"] == 20 * INCR
    # the M6 block waits the tool change time (2.5 s) at standstill
    assert values["ch1.program_time"] >= 2.5


def test_the_tool_change_time_is_the_parameter(c) -> None:
    assert run(c, "G0 X0 Y0 Z0\nM30\n").state == "READY"  # both runs start here
    without = run(c, "T1\nG0 X1\nM30\n")
    assert without.state == "READY"
    time_without = c.read("ch1.program_time")
    assert run(c, "G0 X0\nM30\n").state == "READY"
    with_change = run(c, "T1 M6\nG0 X1\nM30\n")
    assert with_change.state == "READY"
    assert c.read("ch1.program_time") - time_without == pytest.approx(2.5, abs=0.005)
    assert c.read("ch1.mc_active_tool_r") == 1


def test_work_offsets_g54_to_g59_and_g53(c) -> None:
    for group in range(1, 7):  # G54..G59: X offset = 10 * group mm
        c.write(f"ch1.ax1.np_grp[{group}].v", 10.0 * group * INCR)
    c.write("ch1.ax2.np_grp[2].v", -5.0 * INCR)
    for group in range(1, 7):
        status = run(c, f"G0 X0 Y0 Z0\nG{53 + group}\nG0 X1 Y1\nM30\n")
        assert status.state == "READY", errors(c)
        values = c.read_many(["ch1.mc_active_zero_offset_r", "ch1.active_zero_offset_group",
                              "ch1.ax1.command_position_acs", "ch1.ax1.command_position_pcs",
                              "ch1.ax2.command_position_acs", "ch1.ax2.command_position_pcs"])
        assert values["ch1.mc_active_zero_offset_r"] == group
        assert values["ch1.active_zero_offset_group"] == group
        assert values["ch1.ax1.command_position_acs"] == (1 + 10 * group) * INCR
        assert values["ch1.ax1.command_position_pcs"] == 1 * INCR
        y_offset = -5.0 if group == 2 else 0.0
        assert values["ch1.ax2.command_position_acs"] == (1 + y_offset) * INCR
        assert values["ch1.ax2.command_position_pcs"] == 1 * INCR
    status = run(c, "G55\nG0 X0\nG53\nG0 X0\nM30\n")  # G53: back to machine coordinates
    assert status.state == "READY"
    assert c.read("ch1.mc_active_zero_offset_r") == 0
    assert c.read("ch1.ax1.command_position_acs") == 0
    assert c.read("ch1.ax1.command_position_pcs") == 0


def test_g159_selects_the_further_groups(c) -> None:
    c.write("ch1.ax1.np_grp[9].v", 7.5 * INCR)
    assert c.read("ch1.mc_zero_offset_groups_r") == 10
    status = run(c, "G0 X0 Y0 Z0\nG159=9\nG0 X1\nM30\n")
    assert status.state == "READY", errors(c)
    assert c.read("ch1.mc_active_zero_offset_r") == 9
    assert c.read("ch1.ax1.command_position_acs") == 8.5 * INCR


def test_incremental_moves_ignore_a_new_offset(c) -> None:
    """ISG: a new zero offset acts at the next absolute position only (G91 X0 stays)."""
    c.write("ch1.ax1.np_grp[1].v", 10.0 * INCR)
    status = run(c, "G0 X0 Y0 Z0\nG54 G91 X0\nG90\nM30\n")
    assert status.state == "READY"
    assert c.read("ch1.ax1.command_position_acs") == 0


def test_radius_compensation_keeps_taking_the_radius_from_d(c) -> None:
    c.write("ch1.wz[6].radius", 2.0 * INCR)
    c.write("ch1.wz[6].valid", True)
    status = run(c, "G0 X0 Y-10 Z0\nD6\nG41 G1 X0 Y0 F1000\nG1 X20\nG40 G1 X20 Y-10\nM30\n")
    assert status.state == "READY", errors(c)
    assert c.read("ch1.mc_active_tool_radius_r") == 2.0 * INCR


def test_a_written_offset_is_read_back_and_reset_keeps_the_tool(c) -> None:
    c.write("ch1.ax3.np_grp[4].v", -123.4567 * INCR)
    assert c.read("ch1.ax3.np_grp[4].v") == pytest.approx(-123.4567 * INCR)
    run(c, "T2 M6\nD2\nG57\nM30\n")
    c.reset(1)
    values = c.read_many(["ch1.mc_active_tool_r", "ch1.mc_active_tool_offset_r",
                          "ch1.mc_active_zero_offset_r"])
    assert values == {"ch1.mc_active_tool_r": 2, "ch1.mc_active_tool_offset_r": 0,
                      "ch1.mc_active_zero_offset_r": 0}


# ------------------------------------------------------------ bad input


@pytest.mark.parametrize(
    ("program", "error_id", "line", "column"),
    [
        ("G0 X0\nT17 M6\nM30\n", 21915, 2, 1),  # unknown tool: wz[17] is not valid
        ("G0 X0\nD17\nM30\n", 20134, 2, 1),  # D without tool data
        ("G0 X0\nM6\nM30\n", 20137, 2, 1),  # M6 without T
        ("G0 X0\n  G159=10\nM30\n", 20149, 2, 3),  # beyond np_grp[0..9]
        ("G0 X0\nG159=1.5\nM30\n", 20582, 2, 1),  # not a group number
        ("G54 G55\nM30\n", 20116, 1, 5),  # two zero offsets in one block
    ],
)
def test_bad_nc_input_gives_isg_error_ids_with_place(c, program, error_id, line, column) -> None:
    with pytest.raises(ChannelError) as info:
        run(c, program, "bad-tools.nc")
    assert f"error {error_id}: bad-tools.nc:{line}:{column}:" in str(info.value)
    values = c.read_many(["ch1.mc_error_1_id_r", "ch1.mc_error_1_file_r",
                          "ch1.mc_error_1_line_r", "ch1.mc_error_1_column_r"])
    assert values == {"ch1.mc_error_1_id_r": error_id, "ch1.mc_error_1_file_r": "bad-tools.nc",
                      "ch1.mc_error_1_line_r": line, "ch1.mc_error_1_column_r": column}


@pytest.mark.parametrize(
    ("name", "value", "words"),
    [
        ("ch1.wz[3].radius", -1.0, "wz[3].radius = -1"),
        ("ch1.wz[3].laenge", float("inf"), "wz[3].laenge"),
        ("ch1.ax1.np_grp[1].v", 3e9, "np_grp[1] X"),
        ("ch1.ax1.np_grp[1].v", float("nan"), "np_grp[1] X"),
    ],
)
def test_writes_out_of_range_are_refused_with_0x706(c, name, value, words) -> None:
    before = c.read(name)
    with pytest.raises(AdsError) as info:
        c.write(name, value)
    assert info.value.code == 0x706
    assert words in str(info.value) and "outside" in str(info.value)
    assert c.read(name) == before


def test_objects_beyond_the_tables_do_not_exist(c) -> None:
    for name in ("ch1.wz[33].radius", "ch1.ax1.np_grp[10].v", "ch1.ax1.np_grp[0].v"):
        with pytest.raises(AdsError) as info:
            c.read(name)
        assert info.value.code == 0x710 and name in str(info.value)


def test_at_a_stop_the_objects_show_the_offset_of_the_block_that_ran(c: Client) -> None:
    """Issue 39: the decoder has decoded G53 beyond the M0 already; at the stop PCS Z is
    the programmed 10 (machine 60 less G54's 50), the active offset G54's."""
    c.write("ch1.ax3.np_grp[1].v", 50.0 * INCR)
    assert run(c, "G53 G0 X0 Y0 Z0\nM30\n").state == "READY"
    c.upload("stop.nc", b"G54 G0 X0 Y0 Z10\nM0\nG53\nG0 Z20\nG0 X1\nG0 X2\nM30\n")
    c.run_program("stop.nc")
    wait_for(c, "ch1.mc_waiting_for_start_r", True)
    values = c.read_many(["ch1.mc_active_zero_offset_r", "ch1.ax3.command_position_acs",
                          "ch1.ax3.command_position_pcs"])
    assert values == {"ch1.mc_active_zero_offset_r": 1,
                      "ch1.ax3.command_position_acs": 60 * INCR,
                      "ch1.ax3.command_position_pcs": 10 * INCR}
