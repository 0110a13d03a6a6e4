"""``cnc keys new`` and the ``cnc`` command line with keys, against a real service: the
set-up of docs/security.md, step by step."""

from __future__ import annotations

import json
import os
import stat
import subprocess
import sys
from pathlib import Path

import zmq.auth

from cnc_objects.testing import serving

FEED_W, FEED_R = "ch1.mc_command_feed_override_w", "ch1.mc_command_feed_override_r"


def cnc(*args: str, env: dict[str, str] | None = None, cwd: Path | None = None,
        ) -> subprocess.CompletedProcess[str]:
    base = {k: v for k, v in os.environ.items() if k not in ("CNC_KEY", "CNC_SERVER_KEY")}
    return subprocess.run(
        [sys.executable, "-c", "from cnc_objects.clients.cli import main; main()", *args],
        capture_output=True, text=True, timeout=120, env={**base, **(env or {})}, cwd=cwd)


def test_keys_new_writes_a_pair_the_secret_private(tmp_path: Path) -> None:
    made = cnc("--json", "keys", "new", "server", "--dir", str(tmp_path / "svc"))
    assert made.returncode == 0, made.stderr
    record = json.loads(made.stdout)
    public, secret = Path(record["public"]), Path(record["secret"])
    assert public == tmp_path / "svc" / "server.key" and secret.name == "server.key_secret"
    assert stat.S_IMODE(secret.stat().st_mode) == 0o600
    pub_key, secret_key = zmq.auth.load_certificate(secret)
    assert zmq.auth.load_certificate(public) == (pub_key, None) and secret_key
    again = cnc("keys", "new", "server", "--dir", str(tmp_path / "svc"))
    assert again.returncode == 2 and "exists; --force replaces it" in again.stderr
    assert zmq.auth.load_certificate(secret)[0] == pub_key  # untouched
    assert cnc("keys", "new", "server", "--dir", str(tmp_path / "svc"), "--force").returncode == 0
    assert zmq.auth.load_certificate(secret)[0] != pub_key


def test_keys_new_allow_in_places_the_public_key_by_role(tmp_path: Path) -> None:
    svc = tmp_path / "svc"
    assert cnc("keys", "new", "server", "--dir", str(svc)).returncode == 0
    made = cnc("keys", "new", "bob", "--dir", str(tmp_path / "bob"), "--role", "operator",
               "--allow-in", str(svc))
    assert made.returncode == 0, made.stderr
    allowed = svc / "clients" / "operator" / "bob.key"
    assert allowed.read_bytes() == (tmp_path / "bob" / "bob.key").read_bytes()
    assert (tmp_path / "bob" / "server.key").read_bytes() == (svc / "server.key").read_bytes()
    assert f"allowed as operator: {allowed}" in made.stdout
    twice = cnc("keys", "new", "bob", "--dir", str(tmp_path / "bob2"), "--role", "admin",
                "--allow-in", str(svc))
    assert twice.returncode == 2 and "as operator already" in twice.stderr
    bad_role = cnc("keys", "new", "eve", "--role", "boss", "--allow-in", str(svc))
    assert bad_role.returncode == 2 and "unknown role 'boss'" in bad_role.stderr
    no_list = cnc("keys", "new", "eve", "--role", "admin")
    assert no_list.returncode == 2 and "--allow-in" in no_list.stderr
    bad_name = cnc("keys", "new", "../eve", "--dir", str(tmp_path))
    assert bad_name.returncode == 2


def test_the_documented_set_up_with_the_cli(tmp_path: Path) -> None:
    """docs/security.md: keys for the service, a monitor and an operator; the service
    with --keys; the CLI with --key, and with CNC_KEY / CNC_SERVER_KEY."""
    keys = tmp_path / "keys"
    for args in (("server", "--dir", str(keys)),
                 ("panel", "--dir", str(tmp_path / "panel"), "--role", "monitor",
                  "--allow-in", str(keys)),
                 ("alice", "--dir", str(tmp_path / "alice"), "--role", "operator",
                  "--allow-in", str(keys))):
        made = cnc("keys", "new", *args)
        assert made.returncode == 0, made.stderr
    with serving("--keys", str(keys)) as service:
        e = service.endpoint
        monitor = str(tmp_path / "panel" / "panel.key_secret")
        read = cnc("--endpoint", e, "--key", monitor, "read", FEED_R)
        assert read.returncode == 0, read.stderr
        write = cnc("--endpoint", e, "--key", monitor, "write", FEED_W, "500")
        assert write.returncode == 1
        assert write.stderr.strip() == (f"error: ADS 0x704 INVALIDACCESS: role monitor may "
                                        f"not write {FEED_W}; operator or admin may")
        env = {"CNC_KEY": str(tmp_path / "alice" / "alice.key"),  # the secret beside it
               "CNC_SERVER_KEY": str(keys / "server.key")}
        wrote = cnc("--endpoint", e, "write", FEED_W, "50", env=env)  # %
        assert wrote.returncode == 0, wrote.stderr
        got = cnc("--endpoint", e, "--key", monitor, "--json", "read", FEED_R)
        assert json.loads(got.stdout)["raw"] == 500
        upload = cnc("--endpoint", e, "upload", str(tmp_path / "alice" / "alice.key"), env=env)
        assert upload.returncode == 1 and "role operator may not change the program store" \
            in upload.stderr
        service.wait_for_log(r"ZeroMQ client alice \(role operator\) at 127\.0\.0\.1 admitted")
