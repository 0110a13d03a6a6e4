"""``cnc status``, ``cnc reset [--standard]`` and ``cnc run`` on a channel in ERROR, as an
operator meets them, against a fresh service on the virtual clock."""

from __future__ import annotations

from pathlib import Path

from cnc_objects.clients import Client
from tests.support.cli import cnc, json_lines
from tests.support.service import RunningService, home_channel

CLEAN = "N10 G1 X10 Y5 F6000\nN20 M30\n"
BEYOND_LIMIT = "N10 G1 X5000 F100\nN20 M30\n"  # the default X limit is 1000 mm
HAND_CHECK = {"ch1.mc_command_execution_mode_w": 0x48, "ch1.syn_chk.record_result": True}


def nc_file(tmp_path: Path, name: str, text: str) -> str:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return str(path)


def set_up_a_check_by_hand(endpoint: str) -> None:
    """What docs/syntax-check.md shows for a check by hand: SYNCHK | MACHINE_LOCK."""
    with Client(endpoint) as c:
        for name, value in HAND_CHECK.items():
            c.write(name, value)


def test_status_shows_the_execution_mode(service: RunningService, tmp_path: Path) -> None:
    ep = service.endpoint
    lines = cnc("status", endpoint=ep).stdout.splitlines()
    assert lines[1] == "execution mode standard"
    set_up_a_check_by_hand(ep)
    assert cnc("status", endpoint=ep).stdout.splitlines()[1] == (
        "execution mode standard (next start: SYNCHK|MACHINE_LOCK)")
    [record] = json_lines(cnc("--json", "status", endpoint=ep))
    assert (record["execution_mode"], record["commanded_execution_mode"]) == (
        "standard", "SYNCHK|MACHINE_LOCK")
    # A check leaves its mode in effect until the next start; it restores the command.
    with Client(ep) as c:
        c.write("ch1.mc_command_execution_mode_w", 0)
    assert cnc("check", nc_file(tmp_path, "clean.nc", CLEAN), endpoint=ep).returncode == 0
    assert cnc("status", endpoint=ep).stdout.splitlines()[1] == (
        "execution mode SYNCHK|MACHINE_LOCK|SUPPRESS_TECHNO_OUTPUT (next start: standard)")


def test_reset_standard_returns_to_standard_execution(service: RunningService) -> None:
    ep = service.endpoint
    set_up_a_check_by_hand(ep)
    plain = cnc("reset", endpoint=ep)  # RESET only: the commanded mode stays
    assert plain.returncode == 0 and plain.stdout.strip() == "channel 1: reset"
    with Client(ep) as c:
        assert c.read("ch1.mc_command_execution_mode_r") == 0x48
        assert c.read("ch1.syn_chk.record_result") is True
    standard = cnc("reset", "--standard", endpoint=ep)
    assert standard.returncode == 0, standard.stderr
    assert standard.stdout.strip() == "channel 1: reset, standard execution from the next start"
    with Client(ep) as c:
        assert c.read("ch1.mc_command_execution_mode_r") == 0
        assert c.read("ch1.syn_chk.record_result") is False
    assert "--standard" in cnc("reset", "--help").stdout


def test_run_in_error_is_refused_naming_the_error_until_reset(
    service: RunningService, tmp_path: Path
) -> None:
    ep = service.endpoint
    home_channel(ep)  # the software limits count once the axes are referenced
    failed = cnc("run", nc_file(tmp_path, "far.nc", BEYOND_LIMIT), "--wait", endpoint=ep)
    assert failed.returncode == 4, failed.stderr
    good = nc_file(tmp_path, "good.nc", CLEAN)
    for args in (("run", good), ("mdi", "G1 X1 F100"), ("resume",)):
        refused = cnc(*args, endpoint=ep)
        assert refused.returncode == 1, (args, refused.stdout)
        [line] = refused.stderr.splitlines()
        assert line.startswith("error: ADS 0x707 NOTREADY: channel 1 is in ERROR (error 50101: "
                               "far.nc:1:1: axis 1 would reach 5000.0000 mm"), line
        assert "needs a RESET first, which clears the error (cnc reset)" in line
        assert "works" not in line and "working" not in line
    # the service's own words, without the client's rewording: a plain write of the name
    plain = cnc("write", "ch1.mc_command_program_name_w", "good.nc", endpoint=ep)
    assert plain.returncode == 1, plain.stdout
    assert "ADS 0x707" in plain.stderr and "ERROR" in plain.stderr, plain.stderr
    assert "before RESET, which clears the error" in plain.stderr, plain.stderr
    assert "works" not in plain.stderr, plain.stderr
    status = cnc("status", endpoint=ep).stdout.splitlines()
    assert status[-1] == "RESET clears the error (cnc reset)"
    assert cnc("reset", endpoint=ep).returncode == 0
    again = cnc("run", good, "--wait", endpoint=ep)
    assert again.returncode == 0, again.stderr
