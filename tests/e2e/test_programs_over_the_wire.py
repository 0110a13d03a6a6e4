"""Programs over the wire: the store, running, errors, MDI, hold/resume, and the CLI."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest

from cnc_objects.clients import AdsError, ChannelError, Client
from cnc_objects.protocol.constants import PROGRAM_MAX_BYTES, PROGRAM_STORE_GROUP, CncPort
from cnc_objects.protocol.values import ChannelState
from cnc_objects.testing import ServiceProcess, run_program, serving, wait_for
from tests.support.cli import cnc, json_lines

SQUARE = "N10 G1 X10 F6000\nN20 Y10\nN30 X0\nN40 Y0\nN50 M30\n"


@pytest.fixture(scope="module")
def machine() -> Iterator[ServiceProcess]:
    """One service for this module's tests (each starts from RESET)."""
    with serving() as service:
        yield service


@pytest.fixture
def c(machine: ServiceProcess) -> Iterator[Client]:
    with Client(machine.endpoint, timeout_s=10) as client:
        client.reset(1)
        yield client


def test_store_upload_list_download_delete(c: Client) -> None:
    c.upload("square.nc", SQUARE.encode())
    assert ("square.nc", len(SQUARE)) in [(p.name, p.size_bytes) for p in c.programs()]
    assert c.download("square.nc") == SQUARE.encode()
    c.delete_program("square.nc")
    assert "square.nc" not in [p.name for p in c.programs()]


@pytest.mark.parametrize(
    ("name", "code"),
    [("../etc/passwd", 0x706), ("a/b.nc", 0x706), ("x" * 90, 0x706), ("", 0x706)],
)
def test_bad_names_are_refused_and_change_nothing(c: Client, name: str, code: int) -> None:
    before = c.programs()
    with pytest.raises(AdsError) as info:
        c.upload(name, b"M30\n")
    assert info.value.code == code
    assert "name" in str(info.value)
    assert c.programs() == before


def test_a_program_larger_than_a_frame_goes_in_chunks(c: Client) -> None:
    c.upload("big.nc", b"M30\n")
    c.upload("big.nc", b";" * (PROGRAM_MAX_BYTES + 1))  # in chunks, replacing the old
    assert ("big.nc", PROGRAM_MAX_BYTES + 1) in [(p.name, p.size_bytes) for p in c.programs()]


def test_missing_program_is_not_found(c: Client) -> None:
    with pytest.raises(AdsError) as info:
        c.download("nothing.nc")
    assert info.value.code == 0x70C
    with pytest.raises(AdsError) as info:
        c.write("ch1.mc_command_program_name_w", "nothing.nc")
    assert info.value.code == 0x70C


def test_unknown_store_offset(c: Client) -> None:
    with pytest.raises(AdsError) as info:
        c.read_raw(CncPort.COM, PROGRAM_STORE_GROUP, 99, 100)
    assert info.value.code == 0x703


def test_run_square_and_read_the_objects(c: Client) -> None:
    c.upload("square.nc", SQUARE.encode())
    s = run_program(c, "square.nc", timeout_s=30)
    assert (s.mode, s.state, s.program) == ("AUTOMATIC", "READY", "square.nc")
    assert s.positions_mm == {"X": 0.0, "Y": 0.0, "Z": 0.0}
    assert s.block_number == 50 and s.line == 5
    values = c.read_many(["ch1.mc_block_count_r", "ch1.program_time", "ch1.dist_prog_start"])
    assert values["ch1.mc_block_count_r"] == 5
    assert values["ch1.program_time"] > 0.4
    assert values["ch1.dist_prog_start"] == pytest.approx(40 * 10_000, abs=1)


def test_error_is_readable_through_objects(c: Client) -> None:
    c.upload("bad.nc", b"G1 X10 F600\nG1 Y10 Q7\nM30\n")
    c.run_program("bad.nc")
    with pytest.raises(ChannelError) as info:
        c.wait_program(1, timeout_s=30)
    assert "bad.nc:2:" in str(info.value)
    values = c.read_many([
        "ch1.mc_active_state_r", "ch1.mc_error_count_r", "ch1.mc_error_1_id_r",
        "ch1.mc_error_1_file_r", "ch1.mc_error_1_line_r", "ch1.mc_error_1_column_r",
        "ch1.mc_error_1_text_r",
    ])
    assert values["ch1.mc_active_state_r"] == 6
    assert values["ch1.mc_error_count_r"] >= 1
    assert values["ch1.mc_error_1_id_r"] > 0
    assert values["ch1.mc_error_1_file_r"] == "bad.nc"
    assert values["ch1.mc_error_1_line_r"] == 2
    assert values["ch1.mc_error_1_column_r"] == 8  # the Q of "G1 Y10 Q7"
    assert "Q" in values["ch1.mc_error_1_text_r"]
    # The kernel logs every error into its output area, where it can be downloaded at
    # once: the download answers after the writer has written the line (no flush).
    log = c.download_output("errors-ch1.log").decode()
    assert "bad.nc:2:8:" in log.splitlines()[-1]
    assert "errors-ch1.log" in [p.name for p in c.outputs()]
    assert "errors-ch1.log" not in [p.name for p in c.programs()]


def test_start_without_program_is_refused_with_a_reason(c: Client) -> None:
    c.mdi("G0 X0")  # MDI mode: START has nothing selected
    c.wait_program(1, timeout_s=30)
    with pytest.raises(AdsError) as info:
        c.start(1)
    assert info.value.code == 0x707
    assert "READY" in str(info.value)


def test_hold_and_resume_over_the_wire(c: Client) -> None:
    # 30 min of machining: the event-speed clock runs a 30 s move in a few ms of wall
    # time, before the HOLD written after START could arrive
    c.upload("long.nc", b"G1 X300 F10\nG0 X0\nM30\n")
    c.run_program("long.nc")
    c.hold(1)
    assert c.read("ch1.mc_active_state_r") == 5
    wait_for(c, "ch1.actual_path_velocity", 0.0)
    x = c.read("ch1.ax1.command_position_acs")
    assert c.read("ch1.ax1.command_position_acs") == x  # standing
    c.start(1)
    c.wait_program(1, timeout_s=30)
    assert c.read("ax1.actual_position_acs") == 0


def test_cli_run_wait_status(machine: ServiceProcess, tmp_path: Path) -> None:
    program = tmp_path / "cli.nc"
    program.write_text("G1 X12.5 Y-3 F6000\nM30\n")
    result = cnc("run", str(program), "--wait", "--wait-timeout", "30", endpoint=machine.endpoint)
    assert result.returncode == 0, result.stderr
    assert "finished" in result.stdout
    status = cnc("--json", "status", endpoint=machine.endpoint)
    [record] = json_lines(status)
    assert record["positions_mm"] == {"X": 12.5, "Y": -3.0, "Z": 0.0}
    assert record["program"] == "cli.nc" and record["state"] == "READY"
    listed = cnc("programs", endpoint=machine.endpoint)
    assert "cli.nc" in listed.stdout
    out = tmp_path / "back.nc"
    result = cnc("download", "cli.nc", "-o", str(out), endpoint=machine.endpoint)
    assert result.returncode == 0 and out.read_text() == program.read_text()
    cnc("reset", endpoint=machine.endpoint)


def test_cli_wait_reports_the_error(machine: ServiceProcess, tmp_path: Path) -> None:
    program = tmp_path / "broken.nc"
    program.write_text("G1 X1 F600\nG77\nM30\n")
    result = cnc("run", str(program), "--wait", endpoint=machine.endpoint)
    assert result.returncode == 4
    assert "broken.nc:2:" in result.stderr
    status = cnc("status", endpoint=machine.endpoint)
    assert "ERROR" in status.stdout and "broken.nc:2:" in status.stdout
    assert cnc("reset", endpoint=machine.endpoint).returncode == 0


def test_cli_mdi_and_bad_upload(machine: ServiceProcess, tmp_path: Path) -> None:
    result = cnc("mdi", "G90 G1 X3 F600\\nY4", "--wait", endpoint=machine.endpoint)
    assert result.returncode == 0, result.stderr
    status = json_lines(cnc("--json", "status", endpoint=machine.endpoint))[0]
    assert status["positions_mm"]["X"] == 3.0 and status["positions_mm"]["Y"] == 4.0
    program = tmp_path / "ok.nc"
    program.write_text("M30\n")
    bad = cnc("upload", str(program), "--name", "../x.nc", endpoint=machine.endpoint)
    assert bad.returncode == 1 and "0x706" in bad.stderr
    missing = cnc("upload", str(tmp_path / "nope.nc"), endpoint=machine.endpoint)
    assert missing.returncode == 2 and "cannot read" in missing.stderr


def test_a_manual_block_waited_for_leaves_the_channel_ready_for_the_next(c: Client) -> None:
    """``wait_mdi`` returns once the block's run has ended: the next manual block is
    taken at once. Before, the count of finished manual blocks went up when the block
    ended and the channel went back to READY only when the decoder's end arrived, a
    cycle or more later; a loaded machine (CI) refused about 2 in 1000 next blocks with
    NOTREADY (measured with three busy processes on two cores)."""
    refused = []
    for i in range(300):
        try:
            c.wait_mdi(c.mdi(f'#FILE NAME [MSG="next-{i % 3}.txt"]\n#MSG SAVE ["%d", {i}]'),
                       timeout_s=30)
        except AdsError as error:
            refused.append((i, str(error)))
    assert refused == []
    assert c.read("ch1.mc_active_state_r") == ChannelState.READY


def test_cli_lists_downloads_and_deletes_output_files(machine: ServiceProcess, c: Client) -> None:
    c.wait_mdi(c.mdi('#FILE NAME [MSG="cli-out.txt"]\n#MSG SAVE ["hello %d", 7]'), timeout_s=30)
    ep = machine.endpoint
    listed = cnc("outputs", endpoint=ep)
    assert listed.returncode == 0 and "cli-out.txt" in listed.stdout, listed.stderr
    assert "cli-out.txt" not in cnc("programs", endpoint=ep).stdout
    assert cnc("output", "cli-out.txt", endpoint=ep).stdout == "hello 7\n"
    deleted = cnc("delete-output", "cli-out.txt", endpoint=ep)
    assert deleted.returncode == 0 and "deleted output cli-out.txt" in deleted.stdout
    missing = cnc("output", "cli-out.txt", endpoint=ep)
    assert missing.returncode == 1 and "0x70c NOTFOUND" in missing.stderr, missing.stderr
    assert "no output file 'cli-out.txt'" in missing.stderr
