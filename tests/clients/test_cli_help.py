"""``cnc --help`` and ``cnc-mqtt --help`` as a person reads them: flags as flags, one
meaning per option name, the arguments by name in each usage line, nothing rich-only;
and what ``cnc`` imports to start (issue 29, "A quick CLI")."""

from __future__ import annotations

import re
import subprocess
import sys
from collections.abc import Iterator
from typing import Annotated, Any

import pytest
import typer.main

from cnc_objects.clients.cli import app
from cnc_objects.clients.mqtt.cli import app as mqtt_app
from tests.support.cli import cnc

# Heavy modules a command needs only where it uses them (plot: numpy, matplotlib; the
# HMI: textual; service configuration: pydantic; fancy output: rich).
# (argon2: the web users' password hashes, for `cnc web-users` only; issue 36.)
# (asyncua, cryptography: the OPC UA certificate, for `cnc opcua-cert` only; issue 40.)
NOT_FOR_HELP = ("numpy", "pydantic", "rich", "textual", "matplotlib", "msgpack", "zmq",
                "asyncio", "argon2", "asyncua", "cryptography")
NOT_FOR_READ = ("numpy", "pydantic", "rich", "textual", "matplotlib", "argon2", "asyncua",
                "cryptography")
# A read runs on the blocking client: no event loop (asyncio, hence zmq.asyncio), no TLS
# (ssl, which asyncio loads), no CURVE key files (zmq.auth) without keys (issue 36).
NOT_FOR_BLOCKING_READ = ("asyncio", "ssl", "zmq.asyncio", "zmq.auth", "zmq.utils.monitor")


def _commands(group: Any, prefix: tuple[str, ...] = ()) -> Iterator[tuple[tuple[str, ...], Any]]:
    """(words, click command) of every command of ``cnc``, sub-commands included."""
    for name, command in group.commands.items():
        if isinstance(command, typer.core.TyperGroup):
            yield from _commands(command, (*prefix, name))
        else:
            yield (*prefix, name), command


CNC_COMMANDS = list(_commands(typer.main.get_command(app)))


def _help(*words: str) -> str:
    """``cnc WORDS --help``, its program named cnc (run through ``python -c``, it is -c)."""
    result = cnc(*words, "--help", env={"COLUMNS": "100"})
    assert result.returncode == 0, result.stderr
    return re.sub(r"^Usage: \S+", "Usage: cnc", result.stdout)


@pytest.mark.parametrize("words", [w for w, _ in CNC_COMMANDS], ids=" ".join)
def test_every_flag_shows_as_a_flag_and_the_usage_names_the_arguments(
    words: tuple[str, ...]
) -> None:
    shown = _help(*words)
    command = dict(CNC_COMMANDS)[words]
    assert "<bool>" not in shown and "╭" not in shown  # plain help, no rich panels
    usage = shown.splitlines()[0]
    assert usage.startswith(f"Usage: cnc {' '.join(words)} [OPTIONS]")
    assert "{" not in usage  # arguments by name, as in a man page (typer writes {NAME})
    for param in command.params:
        if getattr(param, "is_flag", False) and param.name != "help":
            flag = max(param.opts, key=len)
            assert re.search(rf"^\s+(-\w, )?{re.escape(flag)}( / --no-[\w-]+)?\s{{2}}", shown,
                             re.M), f"{flag} is not shown as a flag:\n{shown}"
        elif param.param_type_name == "argument":
            assert (param.metavar or param.name.upper()).strip("[].") in usage


def test_a_command_registered_anyhow_names_its_arguments_in_capitals() -> None:
    """Commands of other modules and sub-apps, with or without a metavar, get the same
    usage line (``use_usage_command``)."""
    from typer.testing import CliRunner

    from cnc_objects.clients.cli.app import use_usage_command

    demo, sub = typer.Typer(), typer.Typer()
    demo.add_typer(sub, name="sub")

    @demo.command()
    def first(ident: str, more: Annotated[list[str] | None, typer.Argument()] = None) -> None:
        """First."""

    @sub.command()
    def second(names: list[str]) -> None:
        """Second."""

    use_usage_command(demo)
    runner = CliRunner()
    assert "Usage: demo first [OPTIONS] IDENT [MORE...]" in runner.invoke(
        demo, ["first", "--help"], prog_name="demo").output
    assert "Usage: demo sub second [OPTIONS] NAMES..." in runner.invoke(
        demo, ["sub", "second", "--help"], prog_name="demo").output


def test_usage_lines_name_the_program() -> None:
    for words in (("run",), ("check",), ("plot",)):
        assert _help(*words).splitlines()[0] == f"Usage: cnc {words[0]} [OPTIONS] PROGRAM"


def test_timeout_has_one_meaning() -> None:
    """The global --timeout is the reply timeout; a command's own wait is --wait-timeout."""
    assert "--timeout S" in _help()
    for words, command in CNC_COMMANDS:
        names = [opt for p in command.params for opt in p.opts]
        assert "--timeout" not in names, f"cnc {' '.join(words)} has its own --timeout"
    for words in (("run",), ("mdi",), ("resume",), ("check",), ("plot",), ("watch",),
                  ("jog",), ("home",)):
        assert "--wait-timeout S" in _help(*words), words


def test_a_command_option_named_timeout_is_refused() -> None:
    result = cnc("run", "part.nc", "--wait", "--timeout", "1", endpoint="tcp://127.0.0.1:9")
    assert result.returncode == 2 and "No such option: --timeout" in result.stderr


def test_cnc_mqtt_help_is_plain_and_names_the_values() -> None:
    result = subprocess.run(
        [sys.executable, "-c", "from cnc_objects.clients.mqtt.cli import main; main()",
         "--help"], capture_output=True, text=True, timeout=60, env={"COLUMNS": "80",
                                                                    "PATH": "/usr/bin:/bin"})
    assert result.returncode == 0, result.stderr
    shown = result.stdout
    assert "╭" not in shown and "<str>" not in shown and "<bool>" not in shown
    assert max(len(line) for line in shown.splitlines()) <= 80
    for option, value in (("--broker", "HOST[:PORT]"), ("--machine", "NAME"),
                          ("--timeout", "S"), ("--log-level", "LEVEL")):
        assert re.search(rf"^\s+{re.escape(option)} {re.escape(value)}\s", shown, re.M), option
    assert re.search(r"^\s+--tls\s{2}", shown, re.M)
    command = typer.main.get_command(mqtt_app)
    assert all(p.metavar for p in command.params
               if p.param_type_name == "option" and not getattr(p, "is_flag", False))


def _imported_by(*argv: str) -> set[str]:
    """The top-level modules loaded by ``cnc argv`` by the time it exits."""
    return {m.split(".")[0] for m in _modules_of(*argv)}


def _modules_of(*argv: str) -> set[str]:
    """Every module (dotted names) loaded by ``cnc argv`` by the time it exits."""
    code = ("import atexit, sys; atexit.register(lambda: print('MODULES', "
            "' '.join(sorted(sys.modules)), file=sys.stderr)); "
            "from cnc_objects.clients.cli import main; main()")
    result = subprocess.run([sys.executable, "-c", code, *argv], capture_output=True,
                            text=True, timeout=60)
    line = next(x for x in result.stderr.splitlines() if x.startswith("MODULES "))
    return set(line.split()[1:])


def test_web_users_help_names_the_default_file() -> None:
    from cnc_objects.clients.cli.web_users import DEFAULT_FILE_TEXT
    from cnc_objects.clients.web.users import DEFAULT_USERS_FILE

    assert DEFAULT_FILE_TEXT == str(DEFAULT_USERS_FILE)  # the help says the file used


def test_help_imports_no_client_library_and_no_heavy_module() -> None:
    loaded = _imported_by("--help")
    assert "typer" in loaded  # the probe sees what was imported
    assert not loaded & set(NOT_FOR_HELP), sorted(loaded & set(NOT_FOR_HELP))


def test_a_read_imports_what_it_talks_with_and_nothing_heavy(endpoint: str) -> None:
    loaded = _imported_by("--endpoint", endpoint, "read", "cnc_cycle_time_r")
    assert {"zmq", "msgpack"} <= loaded
    assert not loaded & set(NOT_FOR_READ), sorted(loaded & set(NOT_FOR_READ))


def test_a_read_loads_no_event_loop_no_tls_and_not_the_catalog(endpoint: str) -> None:
    """``cnc read NAME`` starts in under 0.25 s (issue 36 point 10): the blocking client
    without asyncio, ssl or CURVE's key loading, and none of the service's catalog
    modules (``objects`` builds them on first use only)."""
    loaded = _modules_of("--endpoint", endpoint, "read", "cnc_cycle_time_r")
    assert "cnc_objects.clients.sync_transport" in loaded  # the probe sees the client
    assert not loaded & set(NOT_FOR_BLOCKING_READ), sorted(loaded & set(NOT_FOR_BLOCKING_READ))
    assert not {m for m in loaded if m.startswith("cnc_objects.objects.catalog")}
