"""``cnc check`` and ``Client.syntax_check`` (ISG FCT-C9) against a real service on the
virtual clock: errors, exit codes, the log, what the check leaves behind."""

from __future__ import annotations

from pathlib import Path

from cnc_objects.clients import Client
from cnc_objects.clients.channel_ops import CheckError, CheckResult, parse_check_log
from tests.support.cli import cnc, json_lines
from tests.support.service import RunningService, home_channel

EXAMPLE_PATH = Path(__file__).resolve().parents[2] / "docs" / "examples" / "check-syntax.nc"
# the example program of the function description (FCT-C9), character for character
SEED_EXAMPLE = EXAMPLE_PATH.read_text(encoding="utf-8")
SEED_ERRORS = [(5, 20113), (8, 20500), (11, 20310), (14, 20151), (17, 20121)]  # (line, id)
CLEAN = "N10 G1 X10 Y5 F6000\nN20 G2 X20 Y5 I5 J0\nN30 M30\n"
BEYOND_LIMIT = "N10 G1 X5000 F100\nN20 M30\n"  # the default X limit is 1000 mm
ERROR_KEYS = {"file", "line", "column", "id", "category", "message"}


def nc_file(tmp_path: Path, name: str, text: str) -> str:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return str(path)


def test_seed_example_reports_its_five_errors(endpoint: str, tmp_path: Path) -> None:
    program = nc_file(tmp_path, "example.nc", SEED_EXAMPLE)
    result = cnc("--json", "check", program, endpoint=endpoint)
    assert result.returncode == 1, result.stderr
    rows = json_lines(result)
    assert all(set(r) == ERROR_KEYS for r in rows), rows
    assert [(r["line"], r["id"]) for r in rows] == SEED_ERRORS
    assert {r["file"] for r in rows} == {"example.nc"}  # uploaded under its base name
    assert [r["category"] for r in rows] == [
        "limit", "command", "assignment", "command", "combination"
    ]
    human = cnc("check", "example.nc", endpoint=endpoint)  # now a stored name
    assert human.returncode == 1, human.stderr
    lines = human.stdout.splitlines()
    assert len(lines) == 5
    assert lines[0].startswith("example.nc:5:13: error 20113 (limit): ")
    assert lines[4] == "example.nc:17:9: error 20121 (combination): G0 and G1 in one block"
    assert human.stderr.strip() == "5 errors in 17 lines"


def test_clean_program_exits_0(endpoint: str, tmp_path: Path) -> None:
    result = cnc("check", nc_file(tmp_path, "clean.nc", CLEAN), endpoint=endpoint)
    assert result.returncode == 0, result.stderr
    assert result.stdout == ""
    assert result.stderr.strip() == "clean: 3 lines"
    result = cnc("--json", "check", "clean.nc", endpoint=endpoint)
    assert result.returncode == 0, result.stderr
    assert result.stdout == "" and result.stderr == ""


def test_errors_total_stops_the_check_early(endpoint: str, tmp_path: Path) -> None:
    program = nc_file(tmp_path, "example.nc", SEED_EXAMPLE)
    result = cnc("--json", "check", program, "--errors-total", "2", endpoint=endpoint)
    assert result.returncode == 1, result.stderr
    assert [(r["line"], r["id"]) for r in json_lines(result)] == SEED_ERRORS[:2]
    human = cnc("check", "example.nc", "--errors-total", "2", endpoint=endpoint)
    assert human.returncode == 1
    assert len(human.stdout.splitlines()) == 2
    assert "stopped early: syn_chk.errors_total reached" in human.stderr
    with Client(endpoint) as c:
        checked = c.syntax_check("example.nc", errors_total=2)
    assert checked.stopped_early and len(checked.errors) == 2 and not checked.clean


def test_log_shows_the_checked_lines(endpoint: str, tmp_path: Path) -> None:
    result = cnc("check", nc_file(tmp_path, "example.nc", SEED_EXAMPLE), "--log",
                 endpoint=endpoint)
    assert result.returncode == 1, result.stderr
    out = result.stdout.splitlines()
    assert out[0] == "; syntax check of example.nc in channel 1"
    for line in ("example.nc:5: N40 G01 X10 F1111111111111111",
                 "example.nc:8: N50 #COMMAND UNKNOWN [...]",
                 "example.nc:17: N80 G00 G01 X100 F1000",
                 "example.nc:19: N130 M30",
                 "error 20121 (combination) at example.nc:17:9: G0 and G1 in one block",
                 "; end: 17 lines, 3 blocks, 5 errors, complete"):
        assert line in out, line
    # after the log, the errors as with plain `check`
    assert out[-1] == "example.nc:17:9: error 20121 (combination): G0 and G1 in one block"
    as_json = cnc("--json", "check", "example.nc", "--log", endpoint=endpoint)
    *errors, log = json_lines(as_json)
    assert len(errors) == 5 and set(log) == {"log"}
    assert "example.nc:19: N130 M30\n" in log["log"]


def test_check_restores_mode_and_parameters(service: RunningService, tmp_path: Path) -> None:
    ep = service.endpoint
    before = {
        "ch1.mc_command_execution_mode_r": 0x80,  # ADD_MDI_BLOCK
        "ch1.syn_chk.errors_per_block": 3,
        "ch1.syn_chk.errors_total": 7,
        "ch1.syn_chk.interactive": True,  # would stop the check after each error
        "ch1.syn_chk.record_result": False,
        "ch1.mc_active_single_block_r": True,  # would stop the check after each line
    }
    with Client(ep) as c:
        c.write("ch1.mc_command_execution_mode_w", 0x80)
        c.write("ch1.syn_chk.errors_per_block", 3)
        c.write("ch1.syn_chk.errors_total", 7)
        c.write("ch1.syn_chk.interactive", True)
        c.write("ch1.mc_command_single_block_w", True)
        assert c.read_many(list(before)) == before
    program = nc_file(tmp_path, "example.nc", SEED_EXAMPLE)
    result = cnc("--json", "check", program, "--errors-total", "4", "--wait-timeout", "60",
                 endpoint=ep)
    assert result.returncode == 1, result.stderr
    assert len(json_lines(result)) == 4  # the check ran with its own settings
    with Client(ep) as c:
        assert c.read_many(list(before)) == before
        assert c.read("ch1.mc_active_execution_mode_r") & 0x48 == 0x48  # it was a check
        assert c.status(1).state == "READY"
    # a check that cannot start restores them too
    missing = cnc("check", "missing.nc", "--errors-total", "1", endpoint=ep)
    assert missing.returncode == 2
    assert "ADS 0x70c NOTFOUND" in missing.stderr
    with Client(ep) as c:
        assert c.read_many(list(before)) == before


def test_check_that_does_not_end_is_reset_after_timeout(
    service: RunningService, tmp_path: Path
) -> None:
    ep = service.endpoint
    with Client(ep) as c:
        c.write("ch1.mc_command_execution_mode_w", 0x80)
    endless = nc_file(tmp_path, "endless.nc",
                      "N10 $WHILE 1 == 1\nN20 G1 X1 F100\nN30 X0\nN40 $ENDWHILE\nN50 M30\n")
    result = cnc("check", endless, "--wait-timeout", "0.5", endpoint=ep)
    assert result.returncode == 2
    assert "did not end within 0.5 s; it is cancelled (RESET)" in result.stderr
    with Client(ep) as c:
        assert c.status(1).state == "READY"
        assert c.read("ch1.mc_command_execution_mode_r") == 0x80
        assert c.read("ch1.syn_chk.record_result") is False


def test_software_limit_violation_aborts(service: RunningService, tmp_path: Path) -> None:
    ep = service.endpoint
    home_channel(ep)  # the software limits count once the axes are referenced
    result = cnc("--json", "check", nc_file(tmp_path, "far.nc", BEYOND_LIMIT), endpoint=ep)
    assert result.returncode == 1, result.stderr
    [abort] = json_lines(result)
    assert set(abort) == ERROR_KEYS
    assert (abort["file"], abort["line"], abort["id"], abort["category"]) == (
        "far.nc", 1, 50101, "abort")
    assert "software limit" in abort["message"]
    status = cnc("status", endpoint=ep)
    assert "AUTOMATIC/ERROR" in status.stdout
    assert "error 50101: far.nc:1:1:" in status.stdout  # in the channel's error list
    again = cnc("check", "far.nc", endpoint=ep)  # refused in ERROR; the log stays
    assert again.returncode == 2
    assert "ADS 0x707 NOTREADY: channel 1 is in ERROR (error 50101: far.nc:1:1:" in again.stderr
    assert "a syntax check needs a RESET first" in again.stderr
    log = cnc("output", "dec01.sc", endpoint=ep).stdout
    assert log.splitlines()[-2:] == [
        "error 50101 (abort) at far.nc:1:1: " + abort["message"],
        "; end: 1 lines, 0 blocks, 0 errors, aborted",
    ]
    assert cnc("reset", endpoint=ep).returncode == 0
    human = cnc("check", "far.nc", endpoint=ep)
    assert human.returncode == 1
    assert human.stdout.startswith("far.nc:1:1: error 50101 (abort): ")
    assert "aborted by error 50101" in human.stderr
    with Client(ep) as c:
        assert c.read("ch1.mc_command_execution_mode_r") == 0
        assert c.read("ch1.syn_chk.record_result") is False


def test_unreachable_service_exits_2() -> None:
    result = cnc("--timeout", "0.3", "check", "part.nc", endpoint="tcp://127.0.0.1:9")
    assert result.returncode == 2
    assert "ADS 0x745 SYNCTIMEOUT" in result.stderr
    assert result.stdout == ""


def test_unreadable_local_file_exits_2(endpoint: str, tmp_path: Path) -> None:
    unreadable = tmp_path / "dir.nc"
    unreadable.mkdir()  # not a file: taken as a stored name, which does not exist
    result = cnc("check", str(unreadable), endpoint=endpoint)
    assert result.returncode == 2
    assert "error:" in result.stderr


def test_check_does_not_move_the_axes(service: RunningService, tmp_path: Path) -> None:
    ep = service.endpoint
    moved = cnc("mdi", "G90 G1 X10 Y5 Z-2 F6000", "--wait", endpoint=ep)
    assert moved.returncode == 0, moved.stderr
    with Client(ep) as c:
        before = c.status(1).positions_mm
    assert before == {"X": 10.0, "Y": 5.0, "Z": -2.0}
    program = nc_file(tmp_path, "moves.nc", "N10 G1 X500 Y-300 Z40 F1000\n"
                      "N20 G2 X520 Y-300 I10 J0\nN30 G0 X0 Y0 Z0\nN40 M30\n")
    result = cnc("check", program, endpoint=ep)
    assert result.returncode == 0, result.stderr
    assert result.stderr.strip() == "clean: 4 lines"
    with Client(ep) as c:
        assert c.status(1).positions_mm == before


def test_client_syntax_check(service: RunningService) -> None:
    home_channel(service.endpoint)  # the software limits count once the axes are referenced
    with Client(service.endpoint) as c:
        c.upload("example.nc", SEED_EXAMPLE.encode())
        c.upload("clean.nc", CLEAN.encode())
        c.upload("far.nc", BEYOND_LIMIT.encode())
        result = c.syntax_check("example.nc", channel=1, timeout_s=60)
        assert isinstance(result, CheckResult) and not result.clean
        assert [(e.line, e.id) for e in result.errors] == SEED_ERRORS
        assert result.errors[4] == CheckError(
            "example.nc", 17, 9, 20121, "combination", "G0 and G1 in one block")
        assert (result.lines, result.blocks) == (17, 3)
        assert result.aborted is None and not result.stopped_early
        assert result.log == c.download_output("dec01.sc").decode()
        assert c.syntax_check("clean.nc").clean
        far = c.syntax_check("far.nc")  # an aborted check is a result, not an exception
        assert not far.clean and far.errors == ()
        assert (far.aborted.id, far.aborted.category, far.aborted.line) == (50101, "abort", 1)
        assert c.status(1).state == "ERROR"
        c.reset(1)
        assert c.read("ch1.mc_command_execution_mode_r") == 0


def test_parse_check_log_handles_colons_in_names_and_messages() -> None:
    log = (
        "; syntax check of a:b.nc in channel 1\n"
        "a:b.nc:1: G1 X1 F100\n"
        "sub:2:3: x.nc:4: Y1\n"
        "error 20121 (combination) at sub:2:3: x.nc:4:7: G0 and G1 in one block\n"
        "error 21220 (term) at a:b.nc:1:9: unknown word 'Q:1:2: '\n"
        "; end: 2 lines, 2 blocks, 2 errors, complete\n"
    )
    result = parse_check_log(log, "a:b.nc")
    assert result.errors == (
        CheckError("sub:2:3: x.nc", 4, 7, 20121, "combination", "G0 and G1 in one block"),
        CheckError("a:b.nc", 1, 9, 21220, "term", "unknown word 'Q:1:2: '"),
    )
    assert (result.lines, result.blocks, result.stopped_early) == (2, 2, False)


def test_parse_check_log_reads_the_count_of_errors_not_listed() -> None:
    log = (
        "; syntax check of big.nc in channel 1\n"
        "error 20111 (combination) at big.nc:1:19: X programmed twice in one block\n"
        "; 41 more errors are not listed (limits.check_max_errors: the first 1 are kept)\n"
        "; end: 2 lines, 2 blocks, 42 errors, complete\n"
    )
    result = parse_check_log(log, "big.nc")
    assert (len(result.errors), result.error_count, result.left_out) == (1, 42, 41)
    assert not result.clean
