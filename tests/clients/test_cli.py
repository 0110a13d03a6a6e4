"""The ``cnc`` command line against a real service: output, JSON lines, exit codes."""

from __future__ import annotations

import contextlib
import os
import pty
import re
import socket
import subprocess
import sys

from tests.support.cli import cnc, json_lines
from tests.support.service import ROOT, RunningService


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
        "name", "port", "group", "offset", "type", "length", "access", "unit", "description",
        "enum", "scale",
    }
    assert rows[0]["scale"] is None  # an axis number: no engineering unit
    assert rows[0]["enum"] == {}  # JSON object keys are strings: "0" for value 0
    assert rows[2]["enum"] == {"0": "LINKED", "1": "REQUESTED", "2": "WAITING_ACK"}
    assert rows[2]["group"] == 0x121302 and rows[2]["offset"] == 0x10018


def test_read_by_name_and_address(endpoint: str) -> None:
    result = cnc("--json", "read", "ch1.ax2.actual_link_to_physical_axis", "cnc_cycle_time_r",
                 endpoint=endpoint)
    assert result.returncode == 0, result.stderr
    assert json_lines(result) == [
        {"name": "ch1.ax2.actual_link_to_physical_axis", "value": 2, "unit": "-"},
        {"name": "cnc_cycle_time_r", "value": 1000, "unit": "us"},
    ]
    result = cnc("read", "--port", "551", "--group", "0x21302", "--offset", "0x20016",
                 "--type", "UNS16", endpoint=endpoint)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "551:0x21302:0x20016 = 2"
    human = cnc("read", "cnc_cycle_time_r", endpoint=endpoint)
    assert human.stdout.strip() == "cnc_cycle_time_r = 1000 (us)"


def test_write_then_read_back(service: RunningService) -> None:
    ep = service.endpoint
    result = cnc("write", "--raw", "ch1.mc_command_feed_override_w", "0x2ee", endpoint=ep)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "ch1.mc_command_feed_override_w := 750 (0.1 %)"
    assert json_lines(cnc("--json", "read", "--raw", "ch1.mc_active_feed_override_r",
                          endpoint=ep)) == [
        {"name": "ch1.mc_active_feed_override_r", "value": 750, "unit": "0.1 %"}
    ]
    result = cnc("--json", "write", "--port", "553", "--group", "0x120101", "--offset", "9",
                 "--type", "UNS16", "500", endpoint=ep)
    assert result.returncode == 0, result.stderr
    assert json_lines(cnc("--json", "read", "ch1.mc_command_feed_override_r", endpoint=ep))[0][
        "raw"
    ] == 500


def test_a_glob_over_command_objects_reads_what_was_last_written(service: RunningService) -> None:
    """Write-only commands (``_w``) read back their last value, so a glob taking them in
    reads as a whole."""
    ep = service.endpoint
    assert cnc("write", "ch2.mc_command_feed_override_w", "64", endpoint=ep).returncode == 0
    result = cnc("--json", "read", "ch2.mc_*_feed_override_*", endpoint=ep)
    assert result.returncode == 0, result.stderr
    values = {row["name"]: (row["value"], row["raw"]) for row in json_lines(result)}
    assert values == {
        "ch2.mc_command_feed_override_w": (64.0, 640),
        "ch2.mc_command_feed_override_r": (64.0, 640),
        "ch2.mc_active_feed_override_r": (64.0, 640),
    }
    assert cnc("write", "ch2.mc_command_feed_override_w", "100", endpoint=ep).returncode == 0


def test_errors_exit_nonzero_with_one_line_naming_the_code(endpoint: str) -> None:
    cases = [
        (("write", "ch1.ax1.link_state", "1"), 1, "ADS 0x704 INVALIDACCESS"),
        (("write", "ch1.mc_command_feed_override_w", "200"), 1, "ADS 0x706 INVALIDDATA"),
        (("write", "ch1.mc_command_feed_override_w", "fast"), 2,
         "error: ch1.mc_command_feed_override_w: 'fast' is not a number of %"),
        (("write", "--raw", "ch1.mc_command_feed_override_w", "fast"), 2,
         "error: ch1.mc_command_feed_override_w: 'fast' is not an integer for UNS16"),
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
    assert all({"name", "value", "unit", "ts", "seq"} == set(r) for r in ticks)
    links = [r for r in rows if r["name"] == "ch1.ax1.link_state"]  # an enumeration
    assert all(r["value_name"] == "LINKED" and r["value"] == 0 for r in links), links


def test_watch_unknown_name_fails_before_printing(endpoint: str) -> None:
    result = cnc("watch", "ch1.ax1.link_state", "nope", "--count", "1", endpoint=endpoint)
    assert result.returncode == 1
    assert result.stdout == ""
    assert "ADS 0x710" in result.stderr


# --------------------------------------------------------------------------- what a user tripped on


def test_values_show_unit_or_enumeration_name_in_parentheses(endpoint: str) -> None:
    human = cnc("read", "cnc_cycle_time_r", "ch1.ax1.link_state", "ch1.ax2.actual_link_to_physical_axis",
                endpoint=endpoint)
    assert human.returncode == 0, human.stderr
    assert human.stdout.splitlines() == [
        "cnc_cycle_time_r = 1000 (us)",
        "ch1.ax1.link_state = 0 (LINKED)",
        "ch1.ax2.actual_link_to_physical_axis = 2",  # no unit, no value names
    ]
    assert json_lines(cnc("--json", "read", "ch1.ax1.link_state", endpoint=endpoint)) == [
        {"name": "ch1.ax1.link_state", "value": 0, "unit": "-", "value_name": "LINKED"}
    ]


def test_negative_values_are_values_not_options(service: RunningService) -> None:
    ep = service.endpoint
    name = "gpCh[0].contour_lookahead.request.start_position"  # REAL64, rw
    result = cnc("write", name, "-1", endpoint=ep)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == f"{name} := -1.0"
    assert json_lines(cnc("--json", "read", name, endpoint=ep))[0]["value"] == -1.0
    # a signed integer reaches the service, which judges it (all bits: refused, named)
    refused = cnc("write", "ch1.mc_command_execution_mode_w", "-1", endpoint=ep)
    assert refused.returncode == 1, refused.stderr
    assert "ADS 0x706 INVALIDDATA" in refused.stderr and "No such option" not in refused.stderr


def test_a_misspelt_name_gets_the_nearest_names(endpoint: str) -> None:
    result = cnc("read", "ch1.mc_activ_state_r", endpoint=endpoint)
    assert result.returncode == 1
    assert result.stderr.startswith(
        "error: ADS 0x710 SYMBOLNOTFOUND: no object 'ch1.mc_activ_state_r'; "
        "did you mean ch1.mc_active_state_r")
    assert len(result.stderr.strip().splitlines()) == 1


def test_a_value_out_of_range_is_refused_by_the_client_without_an_ads_code(endpoint: str) -> None:
    result = cnc("write", "ch1.mc_command_feed_override_w", "-5", endpoint=endpoint)
    assert result.returncode == 2
    assert result.stderr.strip() == (
        "error: ch1.mc_command_feed_override_w: -5 % = -50 (0.1 %): "
        "value -50 out of range for UNS16 (0..65535)")
    result = cnc("write", "--raw", "ch1.mc_command_feed_override_w", "-5", endpoint=endpoint)
    assert result.returncode == 2
    assert result.stderr.strip() == (
        "error: ch1.mc_command_feed_override_w: value -5 out of range for UNS16 (0..65535)")
    result = cnc("write", "--port", "553", "--group", "0x120101", "--offset", "9", "--type",
                 "UNS16", "70000", endpoint=endpoint)
    assert result.returncode == 2
    assert "value 70000 out of range for UNS16 (0..65535)" in result.stderr
    assert "ADS" not in result.stderr


def test_booleans_are_exactly_what_the_message_lists(service: RunningService) -> None:
    ep = service.endpoint
    for word in ("yes", "on", "no", "off"):
        refused = cnc("write", "ch1.mc_command_single_block_w", word, endpoint=ep)
        assert refused.returncode == 2, (word, refused.stdout)
        assert refused.stderr.strip() == (
            f"error: ch1.mc_command_single_block_w: '{word}' is not a boolean (0/1/true/false)")
    assert cnc("write", "ch1.mc_command_single_block_w", "TRUE", endpoint=ep).returncode == 0
    assert json_lines(cnc("--json", "read", "ch1.mc_active_single_block_r", endpoint=ep))[0][
        "value"] is True
    assert cnc("write", "ch1.mc_command_single_block_w", "0", endpoint=ep).returncode == 0


def test_no_reply_names_what_was_asked() -> None:
    # A TCP listener that never answers: ZeroMQ connects, no reply ever comes.
    with socket.socket() as silent:
        silent.bind(("127.0.0.1", 0))
        silent.listen()
        ep = f"tcp://127.0.0.1:{silent.getsockname()[1]}"
        for args, asked in [
            (("read", "ch1.mc_active_state_r"), "READ ch1.mc_active_state_r"),
            (("write", "ch1.mc_command_feed_override_w", "5"), "WRITE ch1.mc_command_feed_override_w"),
            (("status", "-c", "2"), "status of channel 2"),
        ]:
            result = cnc("--timeout", "0.3", *args, endpoint=ep)
            assert result.returncode == 3, (args, result.stderr)
            assert result.stderr.strip() == (
                f"error: ADS 0x745 SYNCTIMEOUT: no reply to {asked} within 0.3 s from {ep} "
                "(is cnc-service running?)")


def test_browse_piped_prints_full_tab_separated_rows(endpoint: str) -> None:
    result = cnc("browse", "*execution_mode.command_w", endpoint=endpoint)  # stdout is a pipe
    assert result.returncode == 0, result.stderr
    header, *rows = result.stdout.splitlines()
    assert header.split("\t") == [
        "name", "port", "group", "offset", "type", "access", "unit", "description"]
    assert [r.split("\t")[0] for r in rows] == [
        "gpCh[0].decoder_mc_control.execution_mode.command_w",
        "gpCh[1].decoder_mc_control.execution_mode.command_w",
    ]
    assert all(len(r.split("\t")) == 8 for r in rows)
    assert max(len(r) for r in rows) > 100  # nothing cut at 80 columns
    assert rows[0].split("\t")[7] == json_lines(
        cnc("--json", "browse", "gpCh?0?.decoder_mc_control.execution_mode.command_w",
            endpoint=endpoint))[0]["description"]


def test_watch_count_on_an_unchanging_value(endpoint: str) -> None:
    # The first sample is the current value, sent at subscription: --count 1 ends at once.
    once = cnc("--json", "watch", "cnc_cycle_time_r", "--count", "1", endpoint=endpoint)
    assert once.returncode == 0, once.stderr
    assert [(r["value"], r["seq"]) for r in json_lines(once)] == [(1000, 1)]
    # A second sample comes only with a change: --wait-timeout bounds the wait (exit 5).
    bounded = cnc("watch", "cnc_cycle_time_r", "--count", "2", "--wait-timeout", "0.5",
                  endpoint=endpoint)
    assert bounded.returncode == 5, bounded.stderr
    assert bounded.stdout.count("cnc_cycle_time_r = 1000 (us)") == 1
    assert "cnc_cycle_time_r 1 of 2" in bounded.stderr
    # Without --count, --wait-timeout is just how long to watch.
    assert cnc("watch", "cnc_cycle_time_r", "--wait-timeout", "0.3", endpoint=endpoint).returncode == 0


def test_browse_on_a_terminal_cuts_nothing(endpoint: str) -> None:
    primary, secondary = pty.openpty()  # stdout is a terminal of 80 columns
    argv = [sys.executable, "-c", "from cnc_objects.clients.cli import main; main()",
            "--endpoint", endpoint, "browse", "*execution_mode.command_w"]
    with subprocess.Popen(argv, cwd=ROOT, stdout=secondary, stderr=subprocess.PIPE,
                          env={**os.environ, "COLUMNS": "80"}) as process:
        os.close(secondary)
        shown = b""
        with contextlib.suppress(OSError):  # EIO once the process has closed the terminal
            while chunk := os.read(primary, 65536):
                shown += chunk
        assert process.wait(timeout=60) == 0, process.stderr.read()  # type: ignore[union-attr]
    os.close(primary)
    text = re.sub(r"\x1b\[[0-9;]*m", "", shown.decode()).replace("\r\n", "\n")
    lines = text.splitlines()
    assert lines[0].split() == [
        "name", "port", "group", "offset", "type", "access", "unit", "description"]
    assert lines[1].startswith("gpCh[0].decoder_mc_control.execution_mode.command_w  851  ")
    assert lines[1].endswith("Execution mode the PLC commands (evaluated at program start "
                             "while enable_w)")
    assert lines[-1] == "2 objects"


def test_the_module_runs_as_the_cnc_script() -> None:
    """``python -m cnc_objects.clients.cli`` is ``cnc`` (it did nothing: no main guard)."""
    result = subprocess.run([sys.executable, "-m", "cnc_objects.clients.cli", "--help"],
                            capture_output=True, text=True, timeout=60)
    assert result.returncode == 0, result.stderr
    assert "Usage: python -m cnc_objects.clients.cli" in result.stdout
    assert "browse" in result.stdout
