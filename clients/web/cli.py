"""``cnc-web``: the web HMI of a cnc-service, at http://127.0.0.1:8080 by default.

    cnc-web [--endpoint URL] [--host H] [--port P] [--users FILE]
            [--key FILE [--server-key FILE]] [--allow-host NAME ...]
            [--max-connections N] [--header-timeout S]
            [--watch-per-page N] [--watch-per-session N] [--watch-total N]
            [--watch-names-per-s N] [--subscribes-in-flight N] [--unwatch-linger-s S]

Browsers sign in as a role with the password ``cnc web-users set ROLE`` stored in the
users file; without that file there is no sign-in and everyone on this machine is an
admin (as loopback peers of a service without keys), which is why cnc-web then serves
loopback only. Without a key (``--key``) it serves loopback only too, as the service
does without keys. Bad usage exits 2 with one line on stderr. Requests must address
cnc-web by one of its names (``--host``, loopback names, ``--allow-host``).
Pages, API, access and limits: docs/web.md.
"""

from __future__ import annotations

import logging
import sys
from pathlib import Path
from typing import NoReturn

import typer

from ..client import DEFAULT_ENDPOINT
from ..key_options import key_option, server_key_option
from . import budgets as watch
from .access import Access
from .connections import HEADER_TIMEOUT_S, MAX_CONNECTIONS, ConnectionLimits, serve
from .hosts import AllowedHosts
from .server import ServiceLink, is_loopback, make_app
from .uploads import IDLE_S
from .users import DEFAULT_USERS_FILE, UsersFile

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
    allow_host: list[str] = typer.Option(
        [], "--allow-host", metavar="NAME", help="Another name browsers reach cnc-web by "
        "(its DNS name); requests naming any other host are refused (DNS rebinding)."),
    max_connections: int = typer.Option(
        MAX_CONNECTIONS, "--max-connections", min=1, help="Connections open at once; one "
        "more is answered 503."),
    header_timeout: float = typer.Option(
        HEADER_TIMEOUT_S, "--header-timeout", min=0.1, metavar="S", help="Seconds a "
        "connection has to send a request's headers; then it is closed."),
    upload_idle: float = typer.Option(
        IDLE_S, "--upload-idle", min=0.1, metavar="S", help="Seconds an upload from a page "
        "waits for its next slice; then it is abandoned (a tab closed mid-upload)."),
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
    watched = None
    if users_file is not None:
        try:
            watched = UsersFile(users_file)
        except ValueError as exc:
            _usage(str(exc))
    loaded = watched.current() if watched is not None else None
    if not is_loopback(host):
        if key is None:
            _usage(f"--host {host} is not loopback: without --key (the service's keys) "
                   "cnc-web serves loopback only")
        if loaded is None:
            _usage(f"--host {host} is not loopback: without a users file everyone would be "
                   "an admin (create one: cnc web-users set operator)")
    access = Access(watched)
    signing = (f"sign-in with {users_file} ({', '.join(r.label for r in loaded.roles)})"
               if loaded else f"no sign-in (every browser of this machine is {access.open_role.label})")
    print(f"cnc-web: http://{host}:{port} for {endpoint}; {signing}", file=sys.stderr, flush=True)
    link = ServiceLink(endpoint, key_file=key, server_key=server_key)
    serve(make_app(link, access, AllowedHosts.serving(host, allow_host), budgets, upload_idle),
          host, port, ConnectionLimits(max_connections, header_timeout))


def main(argv: list[str] | None = None) -> None:
    """Entry point of ``cnc-web`` (``argv``: the options, default the command line)."""
    app(args=argv, prog_name="cnc-web")


if __name__ == "__main__":
    main()
