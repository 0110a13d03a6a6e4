"""docker/Dockerfile and docker/compose.yaml: what can be proven without a Docker engine.

The compose file goes through ``docker compose config`` (or Debian's ``docker-compose``)
wherever one is installed, and its structure is checked everywhere. The Dockerfile's
entry point, command and health check run here as the image would run them.
"""

from __future__ import annotations

import json
import os
import shlex
import shutil
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest
import yaml

from tests.support.service import ROOT, serving

DOCKER = ROOT / "docker"


def _instructions() -> list[tuple[str, str]]:
    """(INSTRUCTION, arguments) of the Dockerfile, continuation lines joined."""
    text = (DOCKER / "Dockerfile").read_text().replace("\\\n", " ")
    out = []
    for line in text.splitlines():
        line = line.strip()
        if line and not line.startswith("#"):
            word, _, rest = line.partition(" ")
            out.append((word.upper(), rest.strip()))
    return out


def _exec_form(args: str) -> list[str]:
    return json.loads(args)


def _compose_cli() -> list[str] | None:
    docker = shutil.which("docker")
    if docker and subprocess.run([docker, "compose", "version"], capture_output=True).returncode == 0:
        return [docker, "compose"]
    legacy = shutil.which("docker-compose")
    return [legacy] if legacy else None


def _compose_from_cli() -> dict:
    """The compose file as ``docker compose config`` resolves it (long forms, ports as
    mappings with integer targets); skipped, with the reason, where no Compose exists."""
    cli = _compose_cli()
    if cli is None:
        pytest.skip("neither `docker compose` nor `docker-compose` is installed: "
                    "the compose file is checked as YAML only")
    result = subprocess.run([*cli, "-f", str(DOCKER / "compose.yaml"), "config"],
                            capture_output=True, text=True, timeout=60)
    assert result.returncode == 0, result.stderr
    return yaml.safe_load(result.stdout)


def _compose_from_yaml() -> dict:
    """The compose file as written (anchors and merge keys resolved by the YAML loader)."""
    return yaml.safe_load((DOCKER / "compose.yaml").read_text())


@pytest.fixture(params=["yaml", "compose-cli"])
def compose(request: pytest.FixtureRequest) -> dict:
    """The compose file read both ways: as YAML everywhere, and through Compose where
    installed, so the checks hold for the short and the resolved long forms."""
    return _compose_from_yaml() if request.param == "yaml" else _compose_from_cli()


def _container_ports(service: dict) -> set[int]:
    """Container-side ports of a service, from short (``"5555:5555"``) or long forms."""
    ports = set()
    for entry in service.get("ports", []):
        if isinstance(entry, dict):
            ports.add(int(entry["target"]))
        else:
            ports.add(int(str(entry).split(":")[-1].split("/")[0]))
    return ports


def test_dockerfile_slim_non_root_entry_point_and_health_check() -> None:
    steps = _instructions()
    kinds = [k for k, _ in steps]
    base = dict(steps)["FROM"]
    assert base.startswith("python:3.11") and base.endswith("-slim")
    user = [a for k, a in steps if k == "USER"]
    assert user and user[-1] not in ("root", "0")
    assert kinds.index("USER") > kinds.index("RUN")  # installs as root, runs as the user
    assert _exec_form(dict(steps)["ENTRYPOINT"]) == ["cnc-service"]
    health = dict(steps)["HEALTHCHECK"]
    assert _exec_form(health.split("CMD", 1)[1].strip())[:1] == ["cnc"]
    assert health.rstrip().endswith('"info"]')


def test_dockerfile_copies_every_package_the_project_installs() -> None:
    copied = {a.split()[0] for k, a in _instructions() if k == "COPY"}
    meta = tomllib.loads((ROOT / "pyproject.toml").read_text())
    packages = set(meta["tool"]["setuptools"]["package-dir"].values())
    assert packages <= copied
    for source in copied:
        assert (ROOT / source).exists(), source
    ignore = (DOCKER / "Dockerfile.dockerignore").read_text().splitlines()
    for source in copied:  # the ignore file lets each of them into the build context
        assert f"!{source}" in ignore or f"!{source}/**" in ignore, source


def _service_exit(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "cnc_objects.service.main", *args],
                          capture_output=True, text=True, timeout=60)


def test_image_command_needs_insecure_for_its_wildcard_endpoint(tmp_path: Path) -> None:
    """Without keys the service refuses 0.0.0.0 (docs/security.md): the image's command
    says --insecure, because inside a container the published port is the boundary."""
    cmd = _exec_form(dict(_instructions())["CMD"])
    assert "--insecure" in cmd and "--keys" not in cmd
    cmd[cmd.index("--program-dir") + 1] = str(tmp_path)
    without = [a for a in cmd if a != "--insecure"]
    refused = _service_exit(*without, "--ads", "off")
    assert refused.returncode == 2
    assert "tcp://0.0.0.0:5555 is not a loopback address" in refused.stderr
    assert "--insecure" in refused.stderr and len(refused.stderr.strip().splitlines()) == 1


def test_image_command_and_health_check_run(tmp_path: Path) -> None:
    """The CMD's options start the service; the HEALTHCHECK's command finds it healthy
    (with the image's CNC_ENDPOINT pointing at it) and unhealthy when it is gone."""
    steps = _instructions()
    cmd = _exec_form(dict(steps)["CMD"])
    assert cmd[cmd.index("--endpoint") + 1] == "tcp://0.0.0.0:5555"
    cmd[cmd.index("--endpoint") + 1] = "tcp://127.0.0.1:*"  # a free port for the test
    cmd[cmd.index("--program-dir") + 1] = str(tmp_path)
    health = _exec_form(dict(steps)["HEALTHCHECK"].split("CMD", 1)[1].strip())
    check = [sys.executable, "-c", "from cnc_objects.clients.cli import main; main()", *health[1:]]
    with serving(*cmd) as service:
        env = {**os.environ, "CNC_ENDPOINT": service.endpoint}
        healthy = subprocess.run(check, env=env, capture_output=True, text=True, timeout=30)
        assert healthy.returncode == 0, healthy.stderr
        assert "ADS state RUN" in healthy.stdout
    gone = subprocess.run(check, env=env, capture_output=True, text=True, timeout=30)
    assert gone.returncode != 0


def test_compose_runs_service_broker_and_bridge(compose: dict) -> None:
    services = {name: s for name, s in compose["services"].items() if not s.get("profiles")}
    assert set(services) == {"cnc", "mosquitto", "mqtt-bridge"}
    cnc, bridge = services["cnc"], services["mqtt-bridge"]
    assert Path(cnc["build"]["dockerfile"]).name == "Dockerfile"
    assert 5555 in _container_ports(cnc)
    assert services["mosquitto"]["image"].startswith("eclipse-mosquitto:")
    assert bridge["image"] == cnc["image"]
    assert bridge["entrypoint"] == ["cnc-mqtt"]
    assert bridge["depends_on"]["cnc"]["condition"] == "service_healthy"
    args = bridge["command"]
    args = shlex.split(args) if isinstance(args, str) else args
    assert args[args.index("--endpoint") + 1] == "tcp://cnc:5555"
    assert args[args.index("--broker") + 1] == "mosquitto:1883"


def _secure_service(compose: dict) -> dict:
    secure = [s for s in compose["services"].values() if "secure" in s.get("profiles", [])]
    assert len(secure) == 1, "one service in the secure profile"
    return secure[0]


def _mounts(service: dict) -> dict[str, tuple[str, bool]]:
    """Container path -> (host source, read-only) of a service's volumes, either form."""
    mounts = {}
    for volume in service.get("volumes", []):
        if isinstance(volume, dict):
            mounts[volume["target"]] = (volume["source"], bool(volume.get("read_only")))
        else:  # SOURCE:TARGET[:MODE]; the source may hold ${VAR:-default}
            head, _, last = volume.rpartition(":")
            if last in ("ro", "rw"):
                source, _, target = head.rpartition(":")
                mounts[target] = (source, last == "ro")
            else:
                mounts[last] = (head, False)
    return mounts


def test_compose_secure_profile_runs_the_service_with_mounted_keys(compose: dict) -> None:
    cnc, secure = compose["services"]["cnc"], _secure_service(compose)
    assert secure["image"] == cnc["image"]
    args = secure["command"]
    args = shlex.split(args) if isinstance(args, str) else args
    assert "--insecure" not in args
    keys = args[args.index("--keys") + 1]
    source, read_only = _mounts(secure)[keys]
    assert read_only and source
    environment = secure["environment"]
    if isinstance(environment, list):
        environment = dict(item.split("=", 1) for item in environment)
    assert environment["CNC_KEY"].startswith(keys + "/")  # the health check's key
    assert 5555 in _container_ports(secure)


def test_secure_profile_command_and_health_check_run(tmp_path: Path) -> None:
    """The secure profile's options start the service on keys made as docs/security.md
    says (``cnc keys new``); the image's health check passes with the profile's CNC_KEY
    and fails without a key."""
    secure = _secure_service(_compose_from_yaml())
    args = list(secure["command"])
    keys_dir = tmp_path / "keys"
    cnc_cli = [sys.executable, "-c", "from cnc_objects.clients.cli import main; main()"]
    for command in (["keys", "new", "server", "--dir", str(keys_dir)],
                    ["keys", "new", "health", "--dir", str(keys_dir), "--role", "monitor",
                     "--allow-in", str(keys_dir)]):
        made = subprocess.run([*cnc_cli, *command], capture_output=True, text=True, timeout=60)
        assert made.returncode == 0, made.stderr
    container_keys = args[args.index("--keys") + 1]
    args[args.index("--keys") + 1] = str(keys_dir)
    args[args.index("--endpoint") + 1] = "tcp://127.0.0.1:*"
    args[args.index("--program-dir") + 1] = str(tmp_path / "programs")
    health = _exec_form(dict(_instructions())["HEALTHCHECK"].split("CMD", 1)[1].strip())
    check = [*cnc_cli, *health[1:]]
    key = secure["environment"]["CNC_KEY"].replace(container_keys, str(keys_dir), 1)
    with serving(*args) as service:
        env = {**os.environ, "CNC_ENDPOINT": service.endpoint, "CNC_KEY": key}
        env.pop("CNC_SERVER_KEY", None)
        healthy = subprocess.run(check, env=env, capture_output=True, text=True, timeout=30)
        assert healthy.returncode == 0, healthy.stderr
        assert "ADS state RUN" in healthy.stdout
        env.pop("CNC_KEY")
        keyless = subprocess.run(check, env=env, capture_output=True, text=True, timeout=30)
        assert keyless.returncode == 3 and "requires a CURVE key" in keyless.stderr


def test_compose_bridge_options_are_the_bridges(compose: dict) -> None:
    """Every option the compose file gives the bridge is one ``cnc-mqtt`` knows."""
    args = compose["services"]["mqtt-bridge"]["command"]
    options = {a for a in args if a.startswith("--")}
    help_text = subprocess.run(
        [sys.executable, "-c", "from cnc_objects.clients.mqtt.cli import main; main()", "--help"],
        capture_output=True, text=True, timeout=30, env={**os.environ, "COLUMNS": "200"},
    ).stdout
    for option in options:
        assert option in help_text, option


def test_mosquitto_config_is_mounted_from_the_project(compose: dict) -> None:
    volumes = compose["services"]["mosquitto"]["volumes"]
    sources = [v["source"] if isinstance(v, dict) else v.split(":")[0] for v in volumes]
    config = [s for s in sources if s.endswith("mosquitto.conf")]
    assert config and (DOCKER / "mosquitto.conf").is_file()
    text = (DOCKER / "mosquitto.conf").read_text()
    assert "listener 1883" in text


def _docker_daemon() -> str:
    """The docker CLI's path when a daemon answers; else skip with the reason."""
    docker = shutil.which("docker")
    if docker is None:
        pytest.skip("no `docker` command: the image is not built here")
    info = subprocess.run([docker, "info", "--format", "{{.ServerVersion}}"],
                          capture_output=True, text=True, timeout=30)
    if info.returncode != 0:
        reason = (info.stderr.strip().splitlines() or ["docker info failed"])[-1]
        pytest.skip(f"no Docker daemon ({reason}): the image is not built here")
    return docker


def test_image_builds_and_serves(tmp_path: Path) -> None:
    """Where a daemon runs: build the image and ask the container's service for its info
    with the image's own health check command."""
    docker = _docker_daemon()
    base = dict(_instructions())["FROM"]
    if subprocess.run([docker, "image", "inspect", base], capture_output=True).returncode:
        pull = subprocess.run([docker, "pull", base], capture_output=True, text=True, timeout=300)
        if pull.returncode != 0:
            pytest.skip(f"base image {base} is not local and cannot be pulled here")
    tag = "cnc-objects:test"
    build = subprocess.run([docker, "build", "-f", str(DOCKER / "Dockerfile"), "-t", tag, str(ROOT)],
                           capture_output=True, text=True, timeout=900)
    assert build.returncode == 0, build.stderr[-4000:]
    container = subprocess.run([docker, "run", "-d", "--rm", tag], capture_output=True, text=True,
                               timeout=60).stdout.strip()
    try:
        health = [*_exec_form(dict(_instructions())["HEALTHCHECK"].split("CMD", 1)[1].strip())]
        for _ in range(30):  # the service needs a moment to bind; `cnc` waits 2 s each try
            done = subprocess.run([docker, "exec", container, *health], capture_output=True,
                                  text=True, timeout=30)
            if done.returncode == 0:
                break
        assert done.returncode == 0, done.stderr
        assert "ADS state RUN" in done.stdout
    finally:
        subprocess.run([docker, "rm", "-f", container], capture_output=True, timeout=60)
