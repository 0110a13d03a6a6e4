"""The cnc-web application: pages, API, the live WebSocket, and the one service client.

``make_app`` builds the aiohttp application; on start-up it opens the ``AsyncClient``
(with the server's CURVE key when given) and the ``LiveHub`` that all WebSockets share;
on clean-up it closes both.
"""

from __future__ import annotations

import asyncio
import ipaddress
from collections.abc import AsyncIterator
from dataclasses import dataclass
from pathlib import Path

from aiohttp import web

from cnc_objects.clients.client import AsyncClient

from . import api, facts, machine_api, program_api
from .access import ACCESS_KEY, Access, session_middleware, sweep_sessions
from .budgets import WatchBudgets
from .closing import OPEN_SOCKETS_KEY, close_open_sockets
from .connections import connection_middleware
from .hosts import HOSTS_KEY, AllowedHosts, host_middleware
from .hub import LiveHub
from .live import HUB_KEY, SOCKETS_KEY, live
from .uploads import IDLE_S, WebUploads

STATIC_DIR = Path(__file__).with_name("static")


@dataclass(frozen=True)
class ServiceLink:
    """How cnc-web reaches the service."""

    endpoint: str
    timeout_s: float = 2.0
    key_file: str | None = None
    server_key: str | None = None

    def client(self) -> AsyncClient:
        """A client of the service (not yet connected)."""
        return AsyncClient(self.endpoint, timeout_s=self.timeout_s, key_file=self.key_file,
                           server_key=self.server_key)


def is_loopback(host: str) -> bool:
    """True when ``host`` is a loopback address or ``localhost``."""
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


async def index(request: web.Request) -> web.StreamResponse:
    """The single page; its views are chosen by the URL's fragment (#machine, ...)."""
    return web.FileResponse(STATIC_DIR / "index.html")


async def no_icon(request: web.Request) -> web.StreamResponse:
    """No favicon: answered, so that browsers do not log a failed request."""
    return web.Response(status=204)


async def stats(request: web.Request) -> web.StreamResponse:
    """What the hub costs the service: subscriptions held, samples received, sockets."""
    hub = request.app[HUB_KEY]
    return web.json_response({"subscriptions": hub.subscriptions,
                              "samples_received": hub.samples_received,
                              "sockets": request.app[SOCKETS_KEY][0]})


def make_app(link: ServiceLink, access: Access, hosts: AllowedHosts,
             budgets: WatchBudgets | None = None,
             upload_idle_s: float = IDLE_S) -> web.Application:
    """The cnc-web application for the service at ``link``, answering requests addressed
    to ``hosts`` only (``budgets``: what pages may watch; default ``WatchBudgets()``;
    ``upload_idle_s``: how long an upload waits for its next slice).
    Each request passes, in order: its connection's guard (the header timer stops), the
    Host/Origin check, the session."""
    app = web.Application(middlewares=[connection_middleware, host_middleware, session_middleware],
                          client_max_size=api.MAX_UPLOAD_BYTES)
    app[ACCESS_KEY] = access
    app[HOSTS_KEY] = hosts
    app[SOCKETS_KEY] = [0]
    app[OPEN_SOCKETS_KEY] = set()
    app.on_shutdown.append(close_open_sockets)

    async def service_client(app: web.Application) -> AsyncIterator[None]:
        client = link.client()
        client.reset_hint = "Reset, beside the MDI line"
        async with client:
            app[api.CLIENT_KEY] = client
            app[HUB_KEY] = LiveHub(client, budgets=budgets)
            # one service connection per upload: the service takes one upload per connection
            app[program_api.UPLOADS_KEY] = uploads = WebUploads(link.client, upload_idle_s)
            sweeper = asyncio.create_task(sweep_sessions(access), name="cnc-web session sweep")
            yield
            sweeper.cancel()
            await uploads.close()
            await app[HUB_KEY].close()
            access.gate.close()

    app.cleanup_ctx.append(service_client)
    app.router.add_get("/", index)
    app.router.add_get("/ws", live)
    app.router.add_get("/favicon.ico", no_icon)
    app.router.add_get("/api/stats", stats)
    app.router.add_static("/static/", STATIC_DIR)
    api.add_routes(app)
    facts.add_routes(app)
    machine_api.add_routes(app)
    program_api.add_routes(app)
    return app
