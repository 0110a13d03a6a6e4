"""``cnc-mqtt``: bridge the objects of a cnc-service to an MQTT broker.

    cnc-mqtt --endpoint URL --broker HOST[:PORT] --machine NAME [--objects PATTERN ...]
             [--writable PATTERN ...] [--username U --password-file F] [--tls]
             [--key FILE [--server-key FILE]]

Runs until SIGINT or SIGTERM (exit code 0, after publishing ``offline``). Bad usage (an
unreadable password file, a broker that is not HOST[:PORT], ...) exits with code 2 and
one line on stderr. Topics, payloads and behaviour: docs/mqtt.md. A service started with
``--keys`` needs the bridge's key (``--key``/``CNC_KEY``; docs/security.md): a key it
refuses is logged as such and retried with the usual backoff.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
import signal
import ssl
import sys
from pathlib import Path
from typing import NoReturn

import typer
import zmq

from ..client import DEFAULT_ENDPOINT
from ..curve import client_curve
from ..errors import ClientValueError
from ..key_options import key_option, server_key_option
from .bridge import Bridge
from .config import DEFAULT_OBJECTS, BridgeConfig, parse_broker

EXIT_USAGE = 2
_LOG_LEVELS = ("DEBUG", "INFO", "WARNING", "ERROR")

# Plain help (no rich panel): each option with its value's name, its help beside it, wrapped
# to the terminal (docs/design-notes.md, "A quick cnc").
app = typer.Typer(add_completion=False, rich_markup_mode=None, help=__doc__.split("\n\n")[0])


def _usage(message: str) -> NoReturn:
    print(f"cnc-mqtt: {message}", file=sys.stderr)
    raise typer.Exit(EXIT_USAGE)


def _read_password(path: Path) -> str:
    """The first line of ``path`` (a trailing newline is not part of the password)."""
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        reason = getattr(exc, "strerror", None) or exc
        _usage(f"cannot read the password file {str(path)!r}: {reason}")
    lines = text.splitlines()
    if not lines or not lines[0]:
        _usage(f"the password file {str(path)!r} is empty")
    return lines[0]


def _check_endpoint(endpoint: str) -> None:
    """ZeroMQ refuses a malformed endpoint at connect; better now than in every retry."""
    sock: zmq.Socket[bytes] = zmq.Context.instance().socket(zmq.DEALER)
    try:
        sock.connect(endpoint)
    except zmq.ZMQError as exc:
        _usage(f"endpoint {endpoint!r}: {exc}")
    finally:
        sock.close(linger=0)


@app.command()
def run(
    endpoint: str = typer.Option(
        DEFAULT_ENDPOINT, "--endpoint", envvar="CNC_ENDPOINT", metavar="URL",
        help="The cnc-service (default $CNC_ENDPOINT, else tcp://127.0.0.1:5555).",
    ),
    broker: str = typer.Option(
        ..., "--broker", metavar="HOST[:PORT]", help="MQTT broker HOST[:PORT] (1883; 8883 with --tls)."
    ),
    machine: str = typer.Option(
        ..., "--machine", metavar="NAME", help="Machine name: topics are cnc/NAME/..."),
    objects: list[str] | None = typer.Option(
        None, "--objects", metavar="GLOB",
        help="Glob of objects to publish; repeat for more; @default = the default set.",
    ),
    writable: list[str] | None = typer.Option(
        None, "--writable", metavar="GLOB",
        help="Glob of objects MQTT clients may write; repeat for more (default: none).",
    ),
    username: str | None = typer.Option(
        None, "--username", metavar="USER", help="Broker user name."),
    password_file: Path | None = typer.Option(
        None, "--password-file", metavar="FILE", help="File whose first line is the broker password."
    ),
    tls: bool = typer.Option(
        False, "--tls", help="TLS to the broker (system CAs, or $SSL_CERT_FILE)."
    ),
    client_id: str | None = typer.Option(
        None, "--client-id", metavar="ID", help="MQTT client id (default cnc-mqtt-NAME)."
    ),
    cycle_ms: int = typer.Option(
        10, "--cycle-ms", min=0, metavar="MS",
        help="Check objects for changes every MS of kernel time (0: every cycle).",
    ),
    timeout_s: float = typer.Option(
        2.0, "--timeout", min=0.01, metavar="S", help="Seconds to wait for a reply of the service."
    ),
    probe_s: float = typer.Option(
        1.0, "--probe-s", min=0.01, metavar="S", help="Seconds between checks that the service is the same."
    ),
    reconnect_initial_s: float = typer.Option(
        0.1, "--reconnect-initial-s", min=0.001, metavar="S", help="First reconnect delay, doubling ..."
    ),
    reconnect_max_s: float = typer.Option(
        5.0, "--reconnect-max-s", min=0.001, metavar="S", help="... up to this."
    ),
    keepalive_s: int = typer.Option(
        30, "--keepalive", min=1, metavar="S", help="MQTT keepalive in seconds."),
    key_file: str | None = key_option("The bridge's"),
    server_key: str | None = server_key_option(),
    log_level: str = typer.Option(
        "INFO", "--log-level", metavar="LEVEL", help="DEBUG, INFO, WARNING or ERROR."),
) -> None:
    """Publish CNC objects to MQTT when they change; write the ones allowed on request."""
    if log_level.upper() not in _LOG_LEVELS:
        _usage(f"unknown log level {log_level!r}")
    try:
        host, port = parse_broker(broker, tls)
    except ValueError as exc:
        _usage(str(exc))
    if password_file is not None and username is None:
        _usage("--password-file needs --username")
    password = _read_password(password_file) if password_file is not None else None
    _check_endpoint(endpoint)
    try:
        client_curve(key_file or None, server_key or None)  # better now than in every retry
    except ClientValueError as exc:
        _usage(str(exc))
    try:
        config = BridgeConfig(
            endpoint, host, machine, broker_port=port,
            objects=tuple(objects or DEFAULT_OBJECTS), writable=tuple(writable or ()),
            username=username, password=password,
            tls_context=ssl.create_default_context() if tls else None,
            client_id=client_id, cycle_ms=cycle_ms, service_timeout_s=timeout_s,
            probe_s=probe_s, reconnect_initial_s=reconnect_initial_s,
            reconnect_max_s=reconnect_max_s, keepalive_s=keepalive_s,
            key_file=key_file or None, server_key=server_key or None,
        )
    except ValueError as exc:
        _usage(str(exc))
    logging.basicConfig(
        level=log_level.upper(), stream=sys.stderr,
        format="%(asctime)s %(levelname)s %(name)s: %(message)s",
    )
    asyncio.run(_serve(config))


async def _serve(config: BridgeConfig) -> None:
    """Run the bridge until SIGINT or SIGTERM cancels it (it then says ``offline``)."""
    task = asyncio.create_task(Bridge(config).run(), name="cnc-mqtt")
    loop = asyncio.get_running_loop()
    for signum in (signal.SIGINT, signal.SIGTERM):
        loop.add_signal_handler(signum, task.cancel)
    with contextlib.suppress(asyncio.CancelledError):
        await task


def main() -> None:
    """Entry point of ``cnc-mqtt``."""
    app()


if __name__ == "__main__":
    main()
