"""``cnc``: read, write, browse and watch CNC objects; run, check and plot NC programs.

    cnc [--endpoint URL] [--key FILE [--server-key FILE]] [--json] [--timeout S] COMMAND ...

The package's ``__init__`` holds the global options and ``main``. The commands live in its
modules ``objects`` (info, browse, read, write, watch), ``machine`` (program store, run,
MDI, hold, resume, reset, status, lookahead, check), ``plot`` (plot), ``keys`` (keys new),
``tools`` (tool, offsets), ``tools_files`` (their export/import), ``step`` (step),
``spindle``, ``manual`` (jog, home), ``alarms``, ``ads`` (ads structure-def), ``web_users``
and ``opcua_cert``; what they share is in
``app``. Importing them here registers them on the app, in this order.

A service started with ``--keys`` needs this client's key (``--key FILE`` or
``CNC_KEY``) and its own public key (``--server-key FILE`` or ``CNC_SERVER_KEY``, by
default ``server.key`` beside the key file); docs/security.md.

Exit codes: 0 done; 1 the service answered with an ADS error; 2 bad usage, or a value the
client refused before sending it (out of range, does not parse, a key file it cannot
use); 3 the service did not answer (timeout, not reachable) or refused this client's key;
commands that wait add their own (see their help).
Every error is one line on stderr: ``error: ADS 0x710 SYMBOLNOTFOUND: ...`` when the
service refused, ``error: ch1.x: value -5 out of range for UNS16 (0..65535)`` when the
client did, ``error: ADS 0x745 SYNCTIMEOUT: no reply to READ ch1.x within 5 s from ...``
when nothing answered.
"""

from __future__ import annotations

import os
import sys

import typer

from ..endpoint import DEFAULT_ENDPOINT

# Importing a command module registers its commands; help lists them in this order.
from . import (
    ads,  # noqa: F401  (ads structure-def)
    alarms,  # noqa: F401  (alarms, alarms ack)
    keys,  # noqa: F401  (keys new)
    machine,  # noqa: F401  (programs, channel commands, check)
    manual,  # noqa: F401  (jog, home)
    objects,  # noqa: F401  (info, browse, read, write, watch)
    opcua_cert,  # noqa: F401  (opcua-cert)
    plot,  # noqa: F401  (plot)
    spindle,  # noqa: F401  (spindle)
    step,  # noqa: F401  (step: the step clock)
    tools,  # noqa: F401  (tool, offsets)
    tools_files,  # noqa: F401  (tool export/import, offsets export/import)
    web_users,  # noqa: F401  (web-users set, remove, list)
)
from .app import Settings, app, use_usage_command

__all__ = ["app", "main"]

use_usage_command(app)  # every command registered above: arguments by name in its usage


@app.callback()
def main_options(
    ctx: typer.Context,
    endpoint: str = typer.Option(
        os.environ.get("CNC_ENDPOINT", DEFAULT_ENDPOINT), "--endpoint", "-e", metavar="URL",
        help="Service endpoint (default: $CNC_ENDPOINT, else tcp://127.0.0.1:5555).",
    ),
    as_json: bool = typer.Option(False, "--json", help="One JSON object per line."),
    timeout_s: float = typer.Option(
        5.0, "--timeout", min=0.01, metavar="S",
        help="Seconds to wait for the service's reply to each request."),
    key_file: str = typer.Option(
        None, "--key", metavar="FILE", envvar="CNC_KEY", show_envvar=False,
        help="This client's CURVE secret key file, for a service with --keys (default: "
        "$CNC_KEY).",
    ),
    server_key: str = typer.Option(
        None, "--server-key", metavar="FILE", envvar="CNC_SERVER_KEY", show_envvar=False,
        help="The service's public key file (default: $CNC_SERVER_KEY, else server.key "
        "beside --key).",
    ),
) -> None:
    """Global options."""
    ctx.obj = Settings(endpoint, as_json, timeout_s, key_file or None, server_key or None)


def main() -> None:
    """Entry point of ``cnc``."""
    try:
        app()
    except KeyboardInterrupt:
        sys.exit(130)

