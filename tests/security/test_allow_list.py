"""The allow-list as the service reads it: key directories by role, ``[security]`` of
the configuration, and every mistake refused at start with one line naming it."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import pytest
import zmq.auth

from cnc_objects.clients import AdsError, AuthenticationError, Client
from cnc_objects.testing import serving
from cnc_objects.testing.process import make_keys

FEED_W = "ch1.mc_command_feed_override_w"


def service_exit(*args: str, tmp_path: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "cnc_objects.service.main", "--clock", "virtual", "--ads",
         "off", "--program-dir", str(tmp_path / "programs"), *args],
        capture_output=True, text=True, timeout=60)


def test_a_misspelt_role_directory_is_refused(tmp_path: Path) -> None:
    keys = make_keys(tmp_path)
    (keys.directory / "clients" / "operator").rename(keys.directory / "clients" / "operators")
    refused = service_exit("--keys", str(keys.directory), tmp_path=tmp_path)
    assert refused.returncode == 2 and len(refused.stderr.splitlines()) == 1
    assert "operators: the allow-list has one directory per role (monitor, operator, " \
        "admin), not 'operators'" in refused.stderr


def test_one_key_with_two_roles_is_refused(tmp_path: Path) -> None:
    keys = make_keys(tmp_path)
    shutil.copyfile(keys.directory / "clients" / "monitor" / "monitor.key",
                    keys.directory / "clients" / "admin" / "again.key")
    refused = service_exit("--keys", str(keys.directory), tmp_path=tmp_path)
    assert refused.returncode == 2 and "one role per key" in refused.stderr


def test_a_missing_or_broken_server_key_is_refused(tmp_path: Path) -> None:
    missing = service_exit("--keys", str(tmp_path / "nowhere"), tmp_path=tmp_path)
    assert missing.returncode == 2
    assert missing.stderr.strip() == (
        f"cnc-service: bad keys: the key file {tmp_path / 'nowhere' / 'server.key_secret'} "
        f"does not exist (make it: cnc keys new server --dir {tmp_path / 'nowhere'})")
    keys = make_keys(tmp_path / "k")
    shutil.copyfile(keys.server_key, keys.directory / "server.key_secret")  # public only
    public_only = service_exit("--keys", str(keys.directory), tmp_path=tmp_path)
    assert public_only.returncode == 2 and "holds no CURVE secret key" in public_only.stderr


def test_security_table_of_the_configuration_with_inline_clients(tmp_path: Path) -> None:
    """``[security] keys_dir`` turns CURVE on without --keys; ``[[security.clients]]``
    adds a client by its public key text."""
    keys = make_keys(tmp_path, roles=("monitor",))
    (tmp_path / "panel").mkdir()
    public_file, secret = zmq.auth.create_certificates(tmp_path / "panel", "panel")
    shutil.copyfile(keys.server_key, tmp_path / "panel" / "server.key")
    public = zmq.auth.load_certificate(public_file)[0].decode()
    config = tmp_path / "machine.toml"
    config.write_text(f'[security]\nkeys_dir = "{keys.directory}"\n'
                      f'[[security.clients]]\nname = "panel"\npublic_key = "{public}"\n'
                      'role = "operator"\n')
    with serving("--config", str(config)) as service:
        with Client(service.endpoint, key_file=secret) as c:
            c.write(FEED_W, 500)
        with Client(service.endpoint, key_file=keys.client("monitor")) as c:
            with pytest.raises(AdsError, match="role monitor may not write"):
                c.write(FEED_W, 600)
        service.wait_for_log(r"allow-list .* and \[\[security\.clients\]\] of the "
                             r"configuration \(monitor 1, operator 1, admin 0\)")
    config.write_text(f'[security]\nkeys_dir = "{keys.directory}"\n[[security.clients]]\n'
                      'name = "x"\npublic_key = "short"\nrole = "admin"\n')
    bad = service_exit("--config", str(config), tmp_path=tmp_path)
    assert bad.returncode == 2
    assert "security.clients.0.public_key: must be the 40 Z85 characters" \
        in bad.stderr


def test_an_empty_allow_list_refuses_everyone_and_says_so(tmp_path: Path) -> None:
    keys = make_keys(tmp_path, roles=())
    with serving("--keys", str(keys.directory)) as service:
        service.wait_for_log("CURVE is on but the allow-list is empty: every client is refused")
        (tmp_path / "eve").mkdir()
        _, secret = zmq.auth.create_certificates(tmp_path / "eve", "eve")
        with pytest.raises(AuthenticationError):
            with Client(service.endpoint, key_file=secret, server_key=keys.server_key) as c:
                c.info()


def test_a_secret_key_in_the_allow_list_is_warned_about(tmp_path: Path) -> None:
    keys = make_keys(tmp_path)
    leaked = keys.directory / "clients" / "operator" / "operator.key_secret"
    shutil.copyfile(keys.client("operator"), leaked)
    with serving("--keys", str(keys.directory)) as service:
        service.wait_for_log(rf"{leaked} is a client's SECRET key: it belongs to the client")
