"""The cnc-web application: pages, API, the live WebSocket, and the one service client.

``make_app`` builds the aiohttp application; on start-up it opens the ``AsyncClient``
(with the server's CURVE key when given) and the ``LiveHub`` that all WebSockets share;
on clean-up it closes both.
"""

from __future__ import annotations

import asyncio
import contextlib
import ipaddress
import json
from collections.abc import AsyncIterator
from dataclasses import dataclass
from pathlib import Path

from aiohttp import WSMsgType, web

from cnc_objects.clients.client import AsyncClient

from . import api, machine_api
from .access import ACCESS_KEY, Access, session_middleware, sweep_sessions
from .connections import connection_middleware
from .hosts import HOSTS_KEY, AllowedHosts, host_middleware
from .hub import FLUSH_S, LiveHub, Outbox

STATIC_DIR = Path(__file__).with_name("static")
HUB_KEY: web.AppKey[LiveHub] = web.AppKey("hub")
SOCKETS_KEY: web.AppKey[list[int]] = web.AppKey("sockets")  # [open WebSockets]
MAX_WATCHED = 2000  # names one browser may watch at once (the objects page's watch list is small)


@dataclass(frozen=True)
class ServiceLink:
    """How cnc-web reaches the service."""

    endpoint: str
    timeout_s: float = 2.0
    key_file: str | None = None
    server_key: str | None = None


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


async def live(request: web.Request) -> web.StreamResponse:
    """The WebSocket: ``{"watch": [names]}`` / ``{"unwatch": [names]}`` from the browser,
    ``{"values": {name: value}, "errors": {name: sentence}}`` to it."""
    hub = request.app[HUB_KEY]
    socket = web.WebSocketResponse(heartbeat=20.0)
    await socket.prepare(request)
    outbox = Outbox()
    request.app[SOCKETS_KEY][0] += 1
    watched: set[str] = set()
    sender = asyncio.create_task(_send(socket, outbox), name="web socket sender")
    try:
        async for message in socket:
            if message.type != WSMsgType.TEXT:
                continue
            try:
                command = json.loads(message.data)
                names = [str(n) for n in command.get("watch", [])]
                dropped = [str(n) for n in command.get("unwatch", [])]
            except (ValueError, AttributeError, TypeError):
                await socket.send_json({"errors": {"": "not a watch message"}})
                continue
            hub.unwatch(outbox, dropped)
            watched.difference_update(dropped)
            names = names[: max(0, MAX_WATCHED - len(watched))]
            watched.update(names)
            hub.watch(outbox, names)
    finally:
        request.app[SOCKETS_KEY][0] -= 1
        hub.unwatch(outbox)
        sender.cancel()
        with contextlib.suppress(asyncio.CancelledError):
            await sender
    return socket


async def _send(socket: web.WebSocketResponse, outbox: Outbox) -> None:
    while not socket.closed:
        await outbox.ready.wait()
        message = outbox.take()
        if message:
            try:
                await socket.send_json(message)
            except ConnectionError:
                return
        await asyncio.sleep(FLUSH_S)  # newer values gather meanwhile: one message for all


def make_app(link: ServiceLink, access: Access, hosts: AllowedHosts) -> web.Application:
    """The cnc-web application for the service at ``link``, answering requests addressed
    to ``hosts`` only. Each request passes, in order: its connection's guard (the header
    timer stops), the Host/Origin check, the session."""
    app = web.Application(middlewares=[connection_middleware, host_middleware, session_middleware],
                          client_max_size=api.MAX_UPLOAD_BYTES)
    app[ACCESS_KEY] = access
    app[HOSTS_KEY] = hosts
    app[SOCKETS_KEY] = [0]

    async def service_client(app: web.Application) -> AsyncIterator[None]:
        client = AsyncClient(link.endpoint, timeout_s=link.timeout_s, key_file=link.key_file,
                             server_key=link.server_key)
        client.reset_hint = "Reset, beside the MDI line"
        async with client:
            app[api.CLIENT_KEY] = client
            app[HUB_KEY] = LiveHub(client)
            sweeper = asyncio.create_task(sweep_sessions(access), name="cnc-web session sweep")
            yield
            sweeper.cancel()
            await app[HUB_KEY].close()
            access.gate.close()

    app.cleanup_ctx.append(service_client)
    app.router.add_get("/", index)
    app.router.add_get("/ws", live)
    app.router.add_get("/favicon.ico", no_icon)
    app.router.add_get("/api/stats", stats)
    app.router.add_static("/static/", STATIC_DIR)
    api.add_routes(app)
    machine_api.add_routes(app)
    return app
