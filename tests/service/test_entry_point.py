"""``cnc-service`` as a process: start-up log, clean stop on signals, bad start-up input."""

from __future__ import annotations

import signal
import subprocess
import sys

import pytest

from cnc_objects.clients import Client
from tests.support.service import ROOT, start_service


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM])
def test_signal_stops_cleanly_with_exit_0(sig: signal.Signals) -> None:
    service = start_service()
    with Client(service.endpoint) as c:
        assert c.read("ch1.ax1.link_state") == 0
    service.process.send_signal(sig)
    assert service.process.wait(10) == 0
    service.wait_for_log("stopped")
    assert not any("Traceback" in line for line in service.log)


def test_realtime_clock_counts_cycles_and_reports_statistics() -> None:
    service = start_service("--clock", "realtime", "--cycle-ms", "2")
    try:
        with Client(service.endpoint) as c:
            assert c.read("cnc_cycle_time_r") == 2000
            first = c.read("cnc_tick_counter_r")
            c.write("ch1.mc_command_feed_override_w", 10)  # applied at a later cycle start
            assert c.read("cnc_tick_counter_r") > first
            stats = c.read_many(["cnc_cycle_overruns_r", "cnc_cycle_jitter_max_r",
                                 "cnc_cycle_exec_time_max_r"])
            assert all(v >= 0 for v in stats.values())
            assert stats["cnc_cycle_exec_time_max_r"] > 0
    finally:
        assert service.stop() == 0


def run_service(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "cnc_objects.service.main", *args], cwd=ROOT, capture_output=True,
        text=True, timeout=30,
    )


def test_bad_configuration_is_refused_naming_the_key(tmp_path) -> None:
    config = tmp_path / "machine.toml"
    config.write_text("cycle_ms = -1\n")
    result = run_service("--config", str(config))
    assert result.returncode == 2
    assert f"{config}: cycle_ms: Input should be greater than 0.05" in result.stderr
    config.write_text('[[physical_axes]]\nnumber = 1\nname = "X"\n')
    result = run_service("--config", str(config))
    assert result.returncode == 2
    # The default channel 1 links Y to physical axis 2, which this file removed.
    assert f"{config}: channels.0.axes.1.link_to: physical axis 2 does not exist" in result.stderr


def test_unreadable_configuration_is_refused(tmp_path) -> None:
    result = run_service("--config", str(tmp_path / "missing.toml"))
    assert result.returncode == 2 and "cannot read" in result.stderr
    broken = tmp_path / "broken.toml"
    broken.write_text("cycle_ms = = 2")
    result = run_service("--config", str(broken))
    assert result.returncode == 2 and "not valid TOML" in result.stderr


def test_endpoint_in_use_is_refused() -> None:
    service = start_service()
    try:
        result = run_service("--endpoint", service.endpoint, "--clock", "virtual")
        assert result.returncode == 2
        assert "cannot listen on" in result.stderr
    finally:
        assert service.stop() == 0


def test_speed_needs_virtual_clock() -> None:
    result = run_service("--speed", "2")
    assert result.returncode == 2 and "--speed" in result.stderr


def test_configuration_file_is_laid_over_the_default(tmp_path) -> None:
    config = tmp_path / "machine.toml"
    config.write_text(
        'name = "mill"\n[[channels]]\nid = 1\nname = "only"\nfeed_override_max = 1200\n'
        '[[channels.axes]]\nname = "X"\nlogical_number = 1\nlink_to = 1\n'
    )
    service = start_service("--config", str(config))
    try:
        with Client(service.endpoint) as c:
            assert c.read("cnc_number_of_channel_r") == 1
            assert c.read("cnc_number_of_axis_r") == 3
            c.write("ch1.mc_command_feed_override_w", 1200)
            assert c.read("ch1.mc_active_feed_override_r") == 1200
            assert c.browse("ch2.*") == []
    finally:
        assert service.stop() == 0
