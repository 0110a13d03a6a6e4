"""``cnc-service`` as a process: start-up log, clean stop on signals, bad start-up input,
where its program store is."""

from __future__ import annotations

import re
import signal
import socket
import struct
import subprocess
from pathlib import Path

import pytest

from cnc_objects.clients import Client
from cnc_objects.testing.process import service_command
from tests.support.entry_point import run_service
from tests.support.service import RunningService, start_service

_STORE_LOG = re.compile(r"program store: (/\S+) \((.+)\)$")


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


@pytest.fixture(autouse=True)
def _in_tmp_path(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Services run without --program-dir here would make ./cnc-data: not in the checkout."""
    monkeypatch.chdir(tmp_path)




def start_in(cwd: Path, *args: str) -> RunningService:
    """``cnc-service *args`` (virtual clock, free port) started in ``cwd``, listening.
    Unlike ``start_service`` it leaves the program store to the service's own rule;
    ``program_dir`` is then the store the service logged."""
    process = subprocess.Popen(
        service_command(*args), cwd=cwd, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE, text=True,
    )
    service = RunningService(process, cwd)
    try:
        line = service.wait_for_log(r"listening on tcp://")
        service.program_dir = store_of(service)[0]
    except BaseException:
        process.kill()
        service.stop()
        raise
    service.endpoint = line.split("listening on ", 1)[1].split()[0]
    return service


def store_of(service: RunningService) -> tuple[Path, str]:
    """The program store the service logged at start, and why it is there."""
    match = _STORE_LOG.search(service.wait_for_log("program store: "))
    assert match, service.log
    return Path(match.group(1)), match.group(2)


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


def test_endpoint_in_use_is_refused_with_one_line() -> None:
    service = start_service()
    try:
        result = run_service("--endpoint", service.endpoint, "--clock", "virtual",
                             "--log-level", "WARNING")
        assert result.returncode == 2
        assert result.stderr.splitlines() == [
            f"cnc-service: cannot listen on {service.endpoint}: Address already in use"
        ]
    finally:
        assert service.stop() == 0


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--clock", "sundial"], "Invalid value for '--clock': "),
        (["--cycle-ms", "fast"], "Invalid value for '--cycle-ms': "),
        (["--log-level", "LOUD"], "Invalid value for '--log-level': "),
        (["--program-dirr", "x"], "No such option: --program-dirr"),
        (["extra"], "unexpected extra argument"),
    ],
)
def test_bad_usage_exits_2_naming_the_option(args: list[str], message: str) -> None:
    result = run_service(*args)
    assert result.returncode == 2
    assert "Usage: cnc-service [OPTIONS]" in result.stderr  # the style of cnc and cnc-mqtt
    assert message in result.stderr
    assert "Traceback" not in result.stderr


def test_help_lists_every_option_with_its_default() -> None:
    result = run_service("--help")
    assert result.returncode == 0
    for option in ("--config", "--endpoint", "--clock", "--speed", "--cycle-ms",
                   "--program-dir", "--data-dir", "--log-level", "--ads", "--ams-net-id"):
        assert option in result.stdout
    assert "[default: tcp://127.0.0.1:5555]" in result.stdout
    assert "realtime|virtual" in result.stdout and "[default: realtime]" in result.stdout


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


def test_default_program_store_belongs_to_the_working_directory(tmp_path: Path) -> None:
    """Two services started in different directories do not share programs; one started
    again where it was started finds its programs again."""
    first_dir, second_dir = tmp_path / "first", tmp_path / "second"
    first_dir.mkdir()
    second_dir.mkdir()
    first, second = start_in(first_dir), start_in(second_dir)
    try:
        first_store, why = store_of(first)
        assert first_store == first_dir.resolve() / "cnc-data" / "programs"
        assert why == "default: cnc-data/programs in the working directory"
        assert store_of(second)[0] == second_dir.resolve() / "cnc-data" / "programs"
        with Client(first.endpoint) as a, Client(second.endpoint) as b:
            a.upload("part.nc", b"G1 X1 F600\nM30\n")
            assert [p.name for p in a.programs()] == ["part.nc"]
            assert b.programs() == []
    finally:
        assert first.stop() == 0 and second.stop() == 0
    assert (first_store / "part.nc").read_bytes() == b"G1 X1 F600\nM30\n"
    again = start_in(first_dir)
    try:
        with Client(again.endpoint) as a:
            assert [p.name for p in a.programs()] == ["part.nc"]
    finally:
        assert again.stop() == 0


def test_data_dir_option_and_configuration_key(tmp_path: Path) -> None:
    config = tmp_path / "machine.toml"
    config.write_text('data_dir = "from-config"\n')
    by_key = start_in(tmp_path, "--config", str(config))
    by_option = start_in(tmp_path, "--config", str(config), "--data-dir", "mill-1")
    try:
        assert store_of(by_key) == (tmp_path.resolve() / "from-config" / "programs",
                                    "data_dir of the configuration")
        assert store_of(by_option) == (tmp_path.resolve() / "mill-1" / "programs",
                                       "--data-dir")
        with Client(by_option.endpoint) as c:
            c.upload("part.nc", b"M30\n")
        assert (tmp_path / "mill-1" / "programs" / "part.nc").is_file()
    finally:
        assert by_key.stop() == 0 and by_option.stop() == 0


def test_program_dir_option_and_key_still_choose_the_store(tmp_path: Path) -> None:
    config = tmp_path / "machine.toml"
    config.write_text('program_store_dir = "progs"\ndata_dir = "data"\n')
    by_key = start_in(tmp_path, "--config", str(config))
    by_option = start_in(tmp_path, "--config", str(config), "--data-dir", "d",
                         "--program-dir", str(tmp_path / "explicit"))
    try:
        assert store_of(by_key) == (tmp_path.resolve() / "progs",
                                    "program_store_dir of the configuration")
        assert store_of(by_option) == (tmp_path.resolve() / "explicit", "--program-dir")
    finally:
        assert by_key.stop() == 0 and by_option.stop() == 0


def test_unusable_program_store_is_refused(tmp_path: Path) -> None:
    (tmp_path / "taken").write_text("a file where the data directory should be")
    result = run_service("--data-dir", "taken")
    assert result.returncode == 2
    assert f"cannot use program directory {tmp_path.resolve() / 'taken' / 'programs'}" in (
        result.stderr)


# --------------------------------------------------------------------------- ADS front end


def _read_state(address: tuple[str, int], net_id: str) -> tuple[int, int, int]:
    """ADS ReadState on port 851 over a raw AMS/TCP connection: (result, ads, device)."""
    target = bytes(int(p) for p in net_id.split("."))
    header = struct.pack("<6sH6sHHHIII", target, 851, bytes([10, 0, 0, 1, 1, 1]), 30000,
                         4, 0x0004, 0, 0, 1)
    with socket.create_connection(address, timeout=10) as sock:
        sock.sendall(struct.pack("<HI", 0, 32) + header)
        reply = b""
        while len(reply) < 6 + 32 + 8:
            chunk = sock.recv(4096)
            assert chunk, "the service closed the connection"
            reply += chunk
    return struct.unpack_from("<IHH", reply, 38)


def test_ads_is_on_by_default_beside_zeromq() -> None:
    from cnc_objects.service.config import build_config
    from cnc_objects.service.main import AdsListen, _ads_listen

    assert _ads_listen(build_config(), None, None) == AdsListen("127.0.0.1", 48898, None)
    assert _ads_listen(build_config(), "off", None) is None
    config = build_config({"ads": {"endpoint": "off", "net_id": "1.2.3.4.5.6"}})
    assert _ads_listen(config, None, None) is None
    assert _ads_listen(config, "127.0.0.9", None) == AdsListen("127.0.0.9", 48898, "1.2.3.4.5.6")
    assert _ads_listen(config, "127.0.0.9:1", "9.9.9.9.1.1") == AdsListen(
        "127.0.0.9", 1, "9.9.9.9.1.1")


def test_both_front_ends_serve_and_say_where(tmp_path: Path) -> None:
    config = tmp_path / "machine.toml"
    config.write_text('[ads]\nnet_id = "5.6.7.8.1.1"\n')
    service = start_service("--config", str(config), ads="127.0.0.1:0")
    try:
        ads_line = service.wait_for_log(r"ADS on ")
        assert service.log.index(ads_line) < service.log.index(
            service.wait_for_log(r"listening on tcp://"))  # ready means both are
        host, port = service.ads_address  # type: ignore[misc]
        assert host == "127.0.0.1" and port > 0
        assert service.ams_net_id == "5.6.7.8.1.1"  # from the configuration
        assert _read_state((host, port), "5.6.7.8.1.1") == (0, 5, 0)  # RUN
        with Client(service.endpoint) as c:
            assert c.read("ch1.ax1.link_state") == 0
    finally:
        assert service.stop() == 0
    service = start_service("--config", str(config), "--ams-net-id", "9.9.9.9.1.1",
                            ads="127.0.0.1:0")
    try:
        assert service.ams_net_id == "9.9.9.9.1.1"  # the option wins
    finally:
        assert service.stop() == 0


def test_the_default_net_id_is_the_ads_address_and_1_1() -> None:
    from cnc_objects.service.ads.server import default_net_id

    assert default_net_id("127.0.0.5") == "127.0.0.5.1.1"
    assert default_net_id("192.0.2.7") == "192.0.2.7.1.1"
    wildcard = default_net_id("0.0.0.0")  # this host's own address instead
    assert wildcard.endswith(".1.1") and not wildcard.startswith("0.0.0.0")


def test_ads_address_in_use_is_refused_with_one_line() -> None:
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        result = run_service("--ads", f"127.0.0.1:{port}", "--endpoint", "tcp://127.0.0.1:*",
                             "--clock", "virtual", "--log-level", "WARNING")
    assert result.returncode == 2
    assert result.stderr.splitlines() == [
        f"cnc-service: cannot listen for ADS on 127.0.0.1:{port}: Address already in use"
    ]


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--ads", "localhost:port"], "cnc-service: bad --ads: 'localhost:port': the port"),
        (["--ads", "::1"], "write an IPv6 host in brackets"),
        (["--ams-net-id", "1.2.3"], "cnc-service: bad --ams-net-id: '1.2.3' is not an AMS Net ID"),
    ],
)
def test_bad_ads_options_exit_2(args: list[str], message: str) -> None:
    result = run_service(*args)
    assert result.returncode == 2 and message in result.stderr
    assert "Traceback" not in result.stderr
