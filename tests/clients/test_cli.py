"""The ``cnc`` command line against a real service: output, JSON lines, exit codes."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

from tests.support.service import ROOT, RunningService


def cnc(
    *args: str, endpoint: str | None = None, env: dict | None = None, cwd: Path | None = None
) -> subprocess.CompletedProcess:
    """Run ``cnc`` as a user would (module entry point of the installed script), in
    ``cwd`` (default: the project root)."""
    argv = [sys.executable, "-c", "from cnc_objects.clients.cli import main; main()"]
    if endpoint is not None:
        argv += ["--endpoint", endpoint]
    return subprocess.run(
        [*argv, *args], cwd=cwd or ROOT, capture_output=True, text=True, timeout=60,
        env={**os.environ, **(env or {})},
    )


def json_lines(result: subprocess.CompletedProcess) -> list[dict]:
    return [json.loads(line) for line in result.stdout.splitlines() if line.strip()]


def test_info(endpoint: str) -> None:
    result = cnc("--json", "info", endpoint=endpoint)
    assert result.returncode == 0, result.stderr
    [record] = json_lines(result)
    assert record["name"] == "cnc-objects" and record["ads_state"] == "RUN"
    human = cnc("info", endpoint=endpoint)
    assert "ADS state RUN" in human.stdout


def test_endpoint_from_environment(endpoint: str) -> None:
    result = cnc("--json", "info", env={"CNC_ENDPOINT": endpoint})
    assert result.returncode == 0, result.stderr


def test_browse_json_keys(endpoint: str) -> None:
    result = cnc("--json", "browse", "ch2.ax1.*link*", endpoint=endpoint)
    assert result.returncode == 0, result.stderr
    rows = json_lines(result)
    assert [r["name"] for r in rows] == [
        "ch2.ax1.requested_link_to_physical_axis",
        "ch2.ax1.actual_link_to_physical_axis",
        "ch2.ax1.link_state",
    ]
    assert set(rows[0]) == {
        "name", "port", "group", "offset", "type", "length", "access", "unit", "description"
    }
    assert rows[2]["group"] == 0x121302 and rows[2]["offset"] == 0x10018


def test_read_by_name_and_address(endpoint: str) -> None:
    result = cnc("--json", "read", "ch1.ax2.actual_link_to_physical_axis", "cnc_cycle_time_r",
                 endpoint=endpoint)
    assert result.returncode == 0, result.stderr
    assert json_lines(result) == [
        {"name": "ch1.ax2.actual_link_to_physical_axis", "value": 2},
        {"name": "cnc_cycle_time_r", "value": 1000},
    ]
    result = cnc("read", "--port", "551", "--group", "0x21302", "--offset", "0x20016",
                 "--type", "UNS16", endpoint=endpoint)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "551:0x21302:0x20016 = 2"
    human = cnc("read", "cnc_cycle_time_r", endpoint=endpoint)
    assert human.stdout.strip() == "cnc_cycle_time_r = 1000 us"


def test_write_then_read_back(service: RunningService) -> None:
    ep = service.endpoint
    result = cnc("write", "ch1.mc_command_feed_override_w", "0x2ee", endpoint=ep)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "ch1.mc_command_feed_override_w := 750"
    assert json_lines(cnc("--json", "read", "ch1.mc_active_feed_override_r", endpoint=ep)) == [
        {"name": "ch1.mc_active_feed_override_r", "value": 750}
    ]
    result = cnc("--json", "write", "--port", "553", "--group", "0x120101", "--offset", "9",
                 "--type", "UNS16", "500", endpoint=ep)
    assert result.returncode == 0, result.stderr
    assert json_lines(cnc("--json", "read", "ch1.mc_command_feed_override_r", endpoint=ep))[0][
        "value"
    ] == 500


def test_errors_exit_nonzero_with_one_line_naming_the_code(endpoint: str) -> None:
    cases = [
        (("read", "ch1.mc_command_execution_mode_w"), 1, "ADS 0x704 INVALIDACCESS"),
        (("write", "ch1.ax1.link_state", "1"), 1, "ADS 0x704 INVALIDACCESS"),
        (("write", "ch1.mc_command_feed_override_w", "2000"), 1, "ADS 0x706 INVALIDDATA"),
        (("write", "ch1.mc_command_feed_override_w", "fast"), 2, "ADS 0x706 INVALIDDATA"),
        (("read", "ch7.nothing"), 1, "ADS 0x710 SYMBOLNOTFOUND"),
        (("read", "--port", "551", "--group", "0x999", "--offset", "0", "--type", "UNS16"), 1,
         "ADS 0x702 INVALIDGRP"),
        (("read", "--port", "551", "--group", "0x121301", "--offset", "0x77", "--type", "UNS16"),
         1, "ADS 0x703 INVALIDOFFSET"),
        (("read", "--port", "551", "--group", "0x121301", "--offset", "0x10018", "--type",
          "UNS16"), 1, "ADS 0x705 INVALIDSIZE"),
    ]
    for args, code, text in cases:
        result = cnc(*args, endpoint=endpoint)
        assert result.returncode == code, (args, result.stdout, result.stderr)
        lines = result.stderr.strip().splitlines()
        assert len(lines) == 1 and text in lines[0], (args, result.stderr)


def test_unreachable_service_exits_3() -> None:
    result = cnc("--timeout", "0.3", "info", endpoint="tcp://127.0.0.1:9")
    assert result.returncode == 3
    assert "ADS 0x745 SYNCTIMEOUT" in result.stderr


def test_usage_errors_exit_2(endpoint: str) -> None:
    assert cnc("read", endpoint=endpoint).returncode == 2
    assert cnc("read", "--port", "551", endpoint=endpoint).returncode == 2
    assert cnc("read", "--port", "x", "--group", "1", "--offset", "1", "--type", "UNS16",
               endpoint=endpoint).returncode == 2
    assert cnc("read", "--port", "551", "--group", "1", "--offset", "1", "--type", "FLOAT9",
               endpoint=endpoint).returncode == 2


def test_watch_prints_count_samples_per_object(endpoint: str) -> None:
    result = cnc("--json", "watch", "ch1.ax1.link_state", "cnc_tick_counter_r", "--count", "2",
                 "--cyclic", "--cycle-ms", "5", endpoint=endpoint)
    assert result.returncode == 0, result.stderr
    rows = json_lines(result)
    assert sorted(r["name"] for r in rows) == ["ch1.ax1.link_state"] * 2 + ["cnc_tick_counter_r"] * 2
    ticks = [r for r in rows if r["name"] == "cnc_tick_counter_r"]
    assert [t["seq"] for t in ticks] == [1, 2] and ticks[1]["value"] > ticks[0]["value"]
    assert all({"name", "value", "ts", "seq"} == set(r) for r in rows)


def test_watch_unknown_name_fails_before_printing(endpoint: str) -> None:
    result = cnc("watch", "ch1.ax1.link_state", "nope", "--count", "1", endpoint=endpoint)
    assert result.returncode == 1
    assert result.stdout == ""
    assert "ADS 0x710" in result.stderr
