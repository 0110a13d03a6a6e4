"""``cnc``: read, write, browse and watch CNC objects; run, check and plot NC programs.

    cnc [--endpoint URL] [--json] [--timeout S] COMMAND ...

The entry module: the global options and ``main``. The commands live in ``cli_objects``
(info, browse, read, write, watch), ``cli_machine`` (program store, run, MDI, hold,
resume, reset, status, lookahead, check) and ``cli_plot`` (plot); what they share is in
``cli_app``. Importing them here registers them on the app, in this order.

Exit codes: 0 done; 1 the service answered with an ADS error; 2 bad usage, or a value the
client refused before sending it (out of range, does not parse); 3 the service did not
answer (timeout, not reachable); commands that wait add their own (see their help).
Every error is one line on stderr: ``error: ADS 0x710 SYMBOLNOTFOUND: ...`` when the
service refused, ``error: ch1.x: value -5 out of range for UNS16 (0..65535)`` when the
client did, ``error: ADS 0x745 SYNCTIMEOUT: no reply to READ ch1.x within 5 s from ...``
when nothing answered.
"""

from __future__ import annotations

import os
import sys

import typer

from .cli_app import Settings, app
from .client import DEFAULT_ENDPOINT

# Importing a command module registers its commands; help lists them in this order.
from . import cli_objects  # noqa: E402,F401,I001  (info, browse, read, write, watch)
from . import cli_machine  # noqa: E402,F401,I001  (programs, channel commands, check)
from . import cli_plot  # noqa: E402,F401,I001  (plot)

__all__ = ["app", "main"]


@app.callback()
def main_options(
    ctx: typer.Context,
    endpoint: str = typer.Option(
        os.environ.get("CNC_ENDPOINT", DEFAULT_ENDPOINT), "--endpoint", "-e",
        help="Service endpoint (default: $CNC_ENDPOINT, else tcp://127.0.0.1:5555).",
    ),
    as_json: bool = typer.Option(False, "--json", help="One JSON object per line."),
    timeout_s: float = typer.Option(5.0, "--timeout", min=0.01, help="Seconds to wait for a reply."),
) -> None:
    """Global options."""
    ctx.obj = Settings(endpoint, as_json, timeout_s)


def main() -> None:
    """Entry point of ``cnc``."""
    try:
        app()
    except KeyboardInterrupt:
        sys.exit(130)
