"""``cnc-web``: the web HMI of a cnc-service, at http://127.0.0.1:8080 by default.

    cnc-web [--endpoint URL] [--host H] [--port P] [--users FILE]
            [--key FILE [--server-key FILE]] [--watch-per-page N] [--watch-per-session N]
            [--watch-total N] [--watch-names-per-s N] [--subscribes-in-flight N]
            [--unwatch-linger-s S]

Browsers sign in as a role with the password ``cnc web-users set ROLE`` stored in the
users file; without that file there is no sign-in and everyone on this machine is an
operator, which is why cnc-web then serves loopback only. Without a key (``--key``) it
serves loopback only too, as the service does without keys. Bad usage exits 2 with one
line on stderr. Pages, API and access: docs/web.md.
"""

from __future__ import annotations

import logging
import sys
from pathlib import Path
from typing import NoReturn

import typer
from aiohttp import web

from ..client import DEFAULT_ENDPOINT
from ..key_options import key_option, server_key_option
from . import budgets as watch
from .access import Access
from .server import ServiceLink, is_loopback, make_app
from .sessions import SessionSigner
from .users import DEFAULT_USERS_FILE, load_users

EXIT_USAGE = 2
DEFAULT_HOST = "127.0.0.1"
DEFAULT_PORT = 8080

app = typer.Typer(add_completion=False, help=__doc__.split("\n\n")[0])


def _usage(message: str) -> NoReturn:
    print(f"cnc-web: {message}", file=sys.stderr)
    raise typer.Exit(EXIT_USAGE)


@app.command()
def run(
    endpoint: str = typer.Option(
        DEFAULT_ENDPOINT, "--endpoint", envvar="CNC_ENDPOINT",
        help="The cnc-service (default $CNC_ENDPOINT, else tcp://127.0.0.1:5555).",
    ),
    host: str = typer.Option(DEFAULT_HOST, "--host", help="Address to serve on (loopback by "
                             "default; another needs --key and a users file)."),
    port: int = typer.Option(DEFAULT_PORT, "--port", min=0, max=65535, help="HTTP port."),
    users: Path = typer.Option(
        None, "--users", metavar="FILE", help="The web users file (default "
        f"{DEFAULT_USERS_FILE} when it exists; without one: no sign-in, loopback only)."),
    key: str = key_option("The web server's"),
    server_key: str = server_key_option(),
    log_level: str = typer.Option("INFO", "--log-level", help="DEBUG, INFO, WARNING or ERROR."),
    watch_per_page: int = typer.Option(
        watch.NAMES_PER_PAGE, "--watch-per-page", min=1,
        help="Objects one page (WebSocket) may watch at once; more are refused to it."),
    watch_per_session: int = typer.Option(
        watch.NAMES_PER_SESSION, "--watch-per-session", min=1,
        help="Objects the pages of one session may watch at once; more are refused to it."),
    watch_total: int = typer.Option(
        watch.NAMES_TOTAL, "--watch-total", min=1,
        help="Objects cnc-web subscribes to for all pages (keep it under the service's "
        "[limits] notifications_per_client)."),
    watch_names_per_s: float = typer.Option(
        watch.NAMES_PER_S, "--watch-names-per-s", min=1.0,
        help="Names a page's watch/unwatch messages may carry per second; a page over it "
        "waits (its messages are read later)."),
    subscribes_in_flight: int = typer.Option(
        watch.SUBSCRIBES_IN_FLIGHT, "--subscribes-in-flight", min=1,
        help="Subscribe requests out to the service at once (others wait in cnc-web)."),
    unwatch_linger_s: float = typer.Option(
        watch.LINGER_S, "--unwatch-linger-s", min=0.0,
        help="Seconds a subscription nobody watches is kept for a page that comes back."),
) -> None:
    """Serve the web HMI."""
    logging.basicConfig(level=log_level.upper(), format="%(levelname)s %(name)s: %(message)s")
    try:
        budgets = watch.WatchBudgets(watch_per_page, watch_per_session, watch_total,
                                     watch_names_per_s, subscribes_in_flight, unwatch_linger_s)
    except ValueError as exc:
        _usage(str(exc))
    users_file = users if users is not None else (
        DEFAULT_USERS_FILE if DEFAULT_USERS_FILE.exists() else None)
    loaded = None
    if users_file is not None:
        try:
            loaded = load_users(users_file)
        except ValueError as exc:
            _usage(str(exc))
    if not is_loopback(host):
        if key is None:
            _usage(f"--host {host} is not loopback: without --key (the service's keys) "
                   "cnc-web serves loopback only")
        if loaded is None:
            _usage(f"--host {host} is not loopback: without a users file everyone would be "
                   "an operator (create one: cnc web-users set operator)")
    access = Access(SessionSigner(), loaded)
    signing = (f"sign-in with {users_file} ({', '.join(r.label for r in loaded.roles)})"
               if loaded else "no sign-in (every browser of this machine is an operator)")
    print(f"cnc-web: http://{host}:{port} for {endpoint}; {signing}", file=sys.stderr, flush=True)
    web.run_app(make_app(ServiceLink(endpoint, key_file=key, server_key=server_key), access,
                         budgets), host=host, port=port, print=None, access_log=None)


def main(argv: list[str] | None = None) -> None:
    """Entry point of ``cnc-web`` (``argv``: the options, default the command line)."""
    app(args=argv, prog_name="cnc-web")


if __name__ == "__main__":
    main()
