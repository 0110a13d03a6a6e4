"""Contour look-ahead over the wire: the docs' CLI walkthrough, the PLC control unit on
port 851, its errors, and reading the marked area while the program runs in real time."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from cnc_objects.clients import AdsError, Client
from cnc_objects.protocol.constants import CncPort
from cnc_objects.testing import ServiceProcess, wait_for
from tests.support.cli import cnc, json_lines

EXAMPLE = Path(__file__).resolve().parents[2] / "docs" / "examples" / "contour-lookahead.nc"
UNIT = "gpCh[0].contour_lookahead"


def cli_json(endpoint: str, *args: str) -> dict:
    result = cnc("--json", *args, endpoint=endpoint)
    assert result.returncode == 0, (args, result.stdout, result.stderr)
    [record] = json_lines(result)
    return record


def test_the_walkthrough_with_the_cli(cnc_service: ServiceProcess) -> None:
    """docs/contour-lookahead.md, "Walkthrough": the same commands, the same numbers."""
    e = cnc_service.endpoint
    ran = cnc("run", str(EXAMPLE), "--wait", endpoint=e)
    assert ran.returncode == 0, ran.stderr
    reply = cli_json(e, "lookahead")
    assert reply["count_logged_blocks"] == 12 and reply["f_log_is_active"] is False
    blocks = reply["blocks"]
    assert [b["block_type"] for b in blocks] == [3, 1, 1, 1, 2, 1, 4, 1, 2, 1, 1, 5]
    arc = blocks[4]  # N40 G3 R10 with the tool (r = 1) inside
    assert (arc["block_number"], arc["programmed_radius"], arc["compensated_radius"]) == (
        40, 100_000.0, 90_000.0)
    assert arc["circle_angle"] == pytest.approx(math.pi / 2)
    assert arc["start_position"] == pytest.approx(410_000.0)
    corner = blocks[8]  # the connecting arc N70 adds around the outside corner
    assert corner["circle_angle"] == pytest.approx(-math.pi / 2)
    assert corner["programmed_radius"] == 0.0 and corner["compensated_radius"] == 10_000.0
    # mode 1 from the middle, mode 2 by distance, the human table
    assert [b["block_number"] for b in cli_json(e, "lookahead", "9")["blocks"]] == [
        70, 80, 90]
    window = cli_json(e, "lookahead", "21", "--length", "20")["blocks"]
    assert [b["block_number"] for b in window] == [30, 40]
    table = cnc("lookahead", "4", endpoint=e)
    assert table.returncode == 0, table.stderr
    assert "12 logged" in table.stdout and "circular" in table.stdout
    assert "90.000" in table.stdout  # the arc's swept angle in degrees
    # the path distance, as GEO object and PLC symbol
    values = cnc("--json", "read", "ch1.dist_prog_start", "gpCh[0].bahn_state.dist_prog_start",
                 endpoint=e)
    distances = [r["raw"] for r in json_lines(values)]  # 0.1 um, as the reply's fields
    assert distances[0] == distances[1] == pytest.approx(blocks[-1]["start_position"])


def test_bad_requests_get_ads_errors_and_clear_messages(cnc_service: ServiceProcess) -> None:
    e = cnc_service.endpoint
    bad_index = cnc("lookahead", "1.5", endpoint=e)
    assert bad_index.returncode == 1
    assert "0x706" in bad_index.stderr and "index" in bad_index.stderr
    not_enabled = cnc("lookahead", "--index", "1", endpoint=e)
    assert not_enabled.returncode == 1
    assert "0x701" in not_enabled.stderr and "FCT_CONTOUR_LAH" in not_enabled.stderr
    with Client(e, timeout_s=10) as c:
        [semaphore] = c.browse(f"{UNIT}.semaphor_rw")
        assert (semaphore.port, semaphore.type, semaphore.access) == (
            CncPort.PLC, "BOOLEAN", "rw")
        with pytest.raises(AdsError) as info:
            c.write(f"{UNIT}.state.count_logged_blocks", 3)
        assert info.value.code == 0x704
        with pytest.raises(AdsError) as info:
            c.write(f"{UNIT}.request.length", math.inf)
        assert info.value.code == 0x706
        assert c.read(f"{UNIT}.request.length") == 0.0  # nothing was stored


@pytest.mark.cnc_service(args=["--clock", "realtime"])
def test_reading_ahead_while_the_program_runs_in_real_time(cnc_client: Client) -> None:
    """Realtime clock: the whole marked area is readable while its first element is
    still running, and during feedhold; the maximum look-ahead distance does not move."""
    lines = "".join(f"N{20 + k} G1 X{10 * (k + 1)} F600\n" for k in range(8))  # 10 mm/s
    program = f"N10 #CONTOUR LOOKAHEAD LOG ON\n{lines}N90 #CONTOUR LOOKAHEAD LOG OFF\nM30\n"
    c = cnc_client
    c.upload("long.nc", program.encode())
    c.run_program("long.nc")
    wait_for(c, "ch1.dist_prog_start", lambda distance: distance > 0.0)  # first motion
    reply = c.contour_lookahead(0)
    assert c.read("ch1.dist_prog_start") < 100_000.0  # still in the first 10 mm element
    assert [b.block_type for b in reply.blocks] == [3] + [1] * 8 + [5]
    assert reply.count_logged_blocks == 10
    assert reply.max_dist_prog_start == pytest.approx(800_000.0)
    c.hold()
    wait_for(c, "ch1.actual_path_velocity", 0.0)
    held = c.contour_lookahead(3)
    assert [b.block_number for b in held.blocks] == [22, 23, 24, 25, 26, 27, 90]
    assert held.max_dist_prog_start == reply.max_dist_prog_start
    window = c.contour_lookahead(300_000.0, 150_000.0)  # elements starting in 30..45 mm
    assert [(b.block_number, b.start_position) for b in window.blocks] == [
        (23, 300_000.0), (24, 400_000.0)]
    c.reset()
