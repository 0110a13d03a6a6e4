"""The README's tour, run as a user types it: every ``$ cnc ...`` line from "## 1." up to
"What runs", in order, in a fresh directory against a fresh service started as `make run`
starts it (realtime clock), and each prints what the README shows under it.

Left out (``readme_tour.NOT_RUN``): the terminal HMI, the lines that need a broker or
containers in the background; their own tests cover them.
"""

from __future__ import annotations

import asyncio
import contextlib
import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

from cnc_objects.testing import ServiceProcess, serving
from cnc_objects.testing.web import serving_web
from tests.e2e.readme_tour import (
    OPCUA_SECTION,
    README_ADS_HOST,
    README_AMS_NET_ID,
    README_ENDPOINT,
    README_OPCUA_URL,
    README_WEB_PORT,
    PythonStep,
    _line_matches,
    machine_section,
    output_matches,
    python_examples,
    readme_web_port,
    tour_items,
    tour_steps,
)
from tests.opcua.conftest import OPCUA_START_S
from tests.support.broker import Watcher, running_broker
from tests.support.service import ROOT

README = ROOT / "README.md"
EXAMPLES = ROOT / "docs" / "examples"


def _env(endpoint: str) -> dict[str, str]:
    return {**os.environ, "CNC_ENDPOINT": endpoint, "COLUMNS": "100",
            "PATH": f"{Path(sys.executable).parent}{os.pathsep}{os.environ['PATH']}"}


def test_the_tour_has_its_steps() -> None:
    commands = [s.command for s in tour_steps(README)]
    for expected in ("cnc info", "cnc run docs/examples/part.nc --wait", "cnc status",
                     "cnc plot part.nc -o part.png", "cnc lookahead", "cnc mdi -c 2 --wait",
                     "cnc check docs/examples/check-syntax.nc", "cnc reset --standard",
                     "cnc run docs/examples/chords.nc --wait", "cnc alarms"):
        assert any(c.startswith(expected) for c in commands), expected
    assert all(s.expected or s.command.startswith("cnc-hmi") for s in tour_steps(README)), \
        [s.command for s in tour_steps(README) if not s.expected]


def test_every_file_the_tour_uses_is_in_docs_examples() -> None:
    """A program named in the tour is a file of docs/examples, given by its path, or the
    store name of one the tour has uploaded (or run) before."""
    stored: set[str] = set()
    for step in tour_steps(README):
        for word in re.findall(r"[\w./-]+\.(?:nc|ecy)\b", step.command):
            if word.startswith("docs/examples/"):
                assert (ROOT / word).is_file(), f"{step.command}: {word} does not exist"
                stored.add(Path(word).name)
            else:
                assert word in stored or word == "copy.nc", \
                    f"{step.command}: {word} was never uploaded before"


@pytest.mark.parametrize(("expected", "actual", "same"), [
    (("a = 1",), ["a = 1"], True),
    (("a = 1",), ["a = 2"], False),
    (("t = 0.306 s",), ["t = 0.309 s"], True),  # a few cycles later
    (("t = 0.306 s",), ["t = 0.318 s"], True),  # a loaded machine: later, never earlier
    (("t = 0.306 s",), ["t = 0.299 s"], False),
    (("t = 0.306 s",), ["t = 0.340 s"], False),
    (("x = 0.306 mm",), ["x = 0.318 mm"], False),  # only durations come late
    (("n = 306",), ["n = 307"], False),  # whole numbers are exact
    (("name  type",), ["name\ttype"], True),
    (("... #1 x = 5",), ["2026-11-25T10:00:00.000+00:00 #1 x = 5"], True),
    (("head", "...", "tail"), ["head", "1", "2", "tail"], True),
    (("head", "...", "tail"), ["head", "1", "2"], False),
    (("x",), ["x", "more"], False),
    ((), ["printed"], False),
])
def test_the_matcher(expected: tuple[str, ...], actual: list[str], same: bool) -> None:
    assert output_matches(expected, actual) is same


def test_every_tour_command_prints_what_the_readme_shows(tmp_path: Path) -> None:
    (tmp_path / "docs").symlink_to(ROOT / "docs")
    with serving("--clock", "realtime", cwd=tmp_path) as service, \
            readme_web_port(), \
            serving_web(service.endpoint, port=README_WEB_PORT, cwd=tmp_path):  # as make run
        env = _env(service.endpoint)
        failures = []
        for step in tour_steps(README):
            done = subprocess.run(["bash", "-c", step.command], cwd=tmp_path, env=env, text=True,
                                  stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=120)
            printed = done.stdout.replace(service.endpoint, README_ENDPOINT)
            if not output_matches(step.expected, printed.splitlines()):
                failures.append(f"$ {step.command}\nREADME shows:\n" + "\n".join(step.expected)
                                + f"\nprinted (exit {done.returncode}):\n{printed}")
        assert not failures, f"{len(failures)} command(s) print otherwise:\n\n" + \
            "\n\n".join(failures)
    assert (tmp_path / "part.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_the_five_axis_step_prints_what_the_readme_shows(tmp_path: Path) -> None:
    """The README's five-axis section on the machine it names (`make run
    MACHINE=five-axis-ac`: ``--machine five-axis-ac``), realtime as `make run`."""
    (tmp_path / "docs").symlink_to(ROOT / "docs")
    steps = machine_section(README)
    assert [s.command.split()[:2] for s in steps] == [["cnc", "run"], ["cnc", "status"]]
    with serving("--clock", "realtime", "--machine", "five-axis-ac", cwd=tmp_path) as service:
        env = _env(service.endpoint)
        for step in steps:
            done = subprocess.run(["bash", "-c", step.command], cwd=tmp_path, env=env,
                                  text=True, stdout=subprocess.PIPE,
                                  stderr=subprocess.STDOUT, timeout=120)
            assert output_matches(step.expected, done.stdout.splitlines()), (
                f"$ {step.command}\nREADME shows:\n" + "\n".join(step.expected)
                + f"\nprinted (exit {done.returncode}):\n{done.stdout}")


def test_the_opcua_step_prints_what_the_readme_shows(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The README's OPC UA example as a script, against a fresh service serving OPC UA
    (on a free port instead of 4840: the URL replaced, as the tour replaces addresses;
    its address space cache in the test's directory, not the user's)."""
    monkeypatch.setenv("CNC_OPCUA_CACHE_DIR", str(tmp_path / "opcua-cache"))
    [(code, shown)] = python_examples(README, OPCUA_SECTION)
    assert README_OPCUA_URL in code
    with serving("--clock", "realtime", "--opcua", "opc.tcp://127.0.0.1:0", cwd=tmp_path,
                 timeout_s=OPCUA_START_S) as service:
        url = re.search(r"OPC UA on (opc\.tcp://\S+)",
                        service.wait_for_log(r"OPC UA on opc\.tcp://\S+"))
        assert url is not None
        script = tmp_path / "opcua_example.py"
        script.write_text(code.replace(README_OPCUA_URL, url.group(1)))
        done = subprocess.run([sys.executable, str(script)], cwd=tmp_path,
                              capture_output=True, text=True, timeout=120)
        assert done.returncode == 0, done.stderr
        assert output_matches(shown, done.stdout.splitlines()), done.stdout


def test_the_python_examples_print_what_the_readme_shows(tmp_path: Path) -> None:
    """The ZeroMQ client, the pyads and the machine functions' examples, each run as a
    script as written (on a fresh service: the tour's state is the next test's), with the
    addresses of `make run` replaced by those of the test's service (ADS on a loopback
    address of its own: AdsLib dials port 48898 of the address it is given)."""
    examples = python_examples(README)
    assert len(examples) == 3 and "pyads" in examples[1][0] and "units=True" in examples[2][0]
    with serving("--clock", "realtime", cwd=tmp_path, ads=True) as service:
        for k, (code, shown) in enumerate(examples):
            script = tmp_path / f"example{k}.py"
            script.write_text(_python_script(code, service))
            done = subprocess.run([sys.executable, str(script)], cwd=tmp_path,
                                  env=_env(service.endpoint), capture_output=True, text=True,
                                  timeout=60)
            assert done.returncode == 0, done.stderr
            assert output_matches(shown, done.stdout.splitlines()), done.stdout


# ------------------------------------------------------------------ the tour in order

_CNC_MQTT_BROKER = "--broker localhost"


def _python_script(code: str, service: ServiceProcess) -> str:
    """An example as written, with the addresses of `make run` replaced by the service's."""
    host = service.ads_address[0]  # type: ignore[index]
    return (code.replace(README_ENDPOINT, service.endpoint)
            .replace(f'"{README_AMS_NET_ID}"', f'"{service.ams_net_id}"')
            .replace(f'"{README_ADS_HOST}"', f'"{host}"'))


async def _shown_by_the_broker(watcher: Watcher, since: int, expected: tuple[str, ...],
                               timeout_s: float = 20.0) -> list[str]:
    """The README's lines of a subscriber (``topic payload``) that no message since
    ``since`` matched within ``timeout_s``: empty when all came."""
    missing = [e for e in expected if e.strip()]
    with contextlib.suppress(TimeoutError):
        async with asyncio.timeout(timeout_s):
            while missing:
                seen = [f"{m.topic.value} {m.payload.decode()}"  # type: ignore[union-attr]
                        for m in watcher.messages[since:]]
                missing = [e for e in missing if not any(_line_matches(e, s) for s in seen)]
                if missing:
                    watcher._arrived.clear()
                    await watcher._arrived.wait()
    return missing


async def test_the_whole_tour_in_order_leaks_no_state(tmp_path: Path) -> None:
    """Issue 36: every step of the tour as a reader takes it, one after another against
    one service: the shell commands, the MQTT bridge's (a broker of the test's own for
    ``mosquitto``, its client for ``mosquitto_sub``/``mosquitto_pub``) and the Python
    examples, the pyads one included. A step that leaves state behind (the MQTT step's
    feed override of 50 %) makes a later one print otherwise than the README shows."""
    (tmp_path / "docs").symlink_to(ROOT / "docs")
    failures: list[str] = []
    bridge: subprocess.Popen[bytes] | None = None
    with serving("--clock", "realtime", cwd=tmp_path, ads=True) as service, \
            readme_web_port(), \
            serving_web(service.endpoint, port=README_WEB_PORT, cwd=tmp_path):
        env = _env(service.endpoint)
        async with running_broker() as broker, contextlib.AsyncExitStack() as stack:
            watcher: Watcher | None = None
            try:
                for item in tour_items(README):
                    if isinstance(item, PythonStep):
                        script = tmp_path / "example.py"
                        script.write_text(_python_script(item.code, service))
                        done = await asyncio.to_thread(
                            subprocess.run, [sys.executable, str(script)], cwd=tmp_path,
                            env=env, capture_output=True, text=True, timeout=120)
                        printed = done.stdout + done.stderr
                        if not output_matches(item.expected, done.stdout.splitlines()):
                            failures.append(f"{item.section}: Python example prints:\n{printed}"
                                            "\nREADME shows:\n" + "\n".join(item.expected))
                        continue
                    command = item.command
                    if command.startswith("mosquitto "):
                        continue  # the test's broker
                    if command.startswith("cnc-mqtt"):
                        argv = command.rstrip("& ").replace(
                            _CNC_MQTT_BROKER, f"--broker {broker.host}:{broker.port}")
                        bridge = subprocess.Popen(["bash", "-c", f"exec {argv}"], cwd=tmp_path,
                                                  env=env, stdout=subprocess.DEVNULL,
                                                  stderr=subprocess.DEVNULL)
                        continue
                    if command.startswith("mosquitto_sub"):
                        topic_filter = shlex.split(command)[-1]
                        watcher = await stack.enter_async_context(Watcher(broker, topic_filter))
                        missing = await _shown_by_the_broker(watcher, 0, item.expected)
                        if missing:
                            topics = {line.split()[0] for line in missing}
                            failures.append(f"$ {command}\nno message shows:\n" + "\n".join(missing)
                                            + "\nseen on those topics:\n" + "\n".join(
                                                f"{m.topic.value} {m.payload!r}"
                                                for m in watcher.messages
                                                if m.topic.value in topics))
                        continue
                    if command.startswith("mosquitto_pub"):
                        assert watcher is not None, "mosquitto_pub before mosquitto_sub"
                        words = shlex.split(command)
                        since = watcher.mark()
                        await watcher.client.publish(words[words.index("-t") + 1],
                                                     words[words.index("-m") + 1], qos=1)
                        missing = await _shown_by_the_broker(watcher, since, item.expected)
                        if missing:
                            failures.append(f"$ {command}\nno message shows:\n" + "\n".join(missing))
                        continue
                    done = await asyncio.to_thread(
                        subprocess.run, ["bash", "-c", command], cwd=tmp_path, env=env,
                        text=True, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=120)
                    printed = done.stdout.replace(service.endpoint, README_ENDPOINT)
                    if not output_matches(item.expected, printed.splitlines()):
                        failures.append(f"$ {command}\nREADME shows:\n" + "\n".join(item.expected)
                                        + f"\nprinted (exit {done.returncode}):\n{printed}")
            finally:
                if bridge is not None:
                    bridge.terminate()
                    bridge.wait(timeout=10)
    assert bridge is not None and watcher is not None, "the tour has no MQTT step"
    assert not failures, f"{len(failures)} step(s) print otherwise:\n\n" + "\n\n".join(failures)
