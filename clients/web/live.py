"""The live WebSocket of cnc-web: a page says what it watches, the hub sends the values.

``{"watch": [names]}`` / ``{"unwatch": [names]}`` from the browser, ``{"values": {name:
value}, "errors": {name: sentence}}`` to it, at most every ``FLUSH_S``. The page's
session (its signed cookie) is what ``names_per_session`` counts against, and its
messages are read at ``names_per_s`` names a second at most (``budgets.WatchBudgets``:
a page that watches and unwatches in a loop is slowed, not refused). A message that is
not a watch message is answered with an error under the empty name and changes nothing.
"""

from __future__ import annotations

import asyncio
import contextlib
import json

from aiohttp import WSMsgType, web

from .access import current_session
from .budgets import NameRate
from .closing import OPEN_SOCKETS_KEY
from .hub import FLUSH_S, LiveHub, Outbox

HUB_KEY: web.AppKey[LiveHub] = web.AppKey("hub")
SOCKETS_KEY: web.AppKey[list[int]] = web.AppKey("sockets")  # [open WebSockets]
NOT_A_WATCH_MESSAGE = "not a watch message: send {\"watch\": [names]} or {\"unwatch\": [names]}"


def _names(command: object, key: str) -> list[str]:
    """The list of names under ``key`` of a watch message (``ValueError`` if it is none)."""
    if not isinstance(command, dict):
        raise ValueError(NOT_A_WATCH_MESSAGE)
    names = command.get(key, [])
    if not isinstance(names, list) or not all(isinstance(n, str) for n in names):
        raise ValueError(NOT_A_WATCH_MESSAGE)
    return names


async def live(request: web.Request) -> web.StreamResponse:
    """The WebSocket (see the module docstring)."""
    hub = request.app[HUB_KEY]
    socket = web.WebSocketResponse(heartbeat=20.0)
    await socket.prepare(request)
    outbox = Outbox(current_session(request).csrf)  # the csrf token names the session
    request.app[SOCKETS_KEY][0] += 1
    request.app[OPEN_SOCKETS_KEY].add(socket)  # closed by cnc-web's shutdown (closing.py)
    sender = asyncio.create_task(_send(socket, outbox), name="web socket sender")
    rate = NameRate(hub.budgets.names_per_s)
    try:
        async for message in socket:
            if message.type != WSMsgType.TEXT:
                continue
            try:
                command = json.loads(message.data)
                names, dropped = _names(command, "watch"), _names(command, "unwatch")
            except ValueError:
                outbox.refuse("", NOT_A_WATCH_MESSAGE)
                continue
            if not await rate.spend(len(names) + len(dropped), lambda: _gone(request)):
                break  # a page over its rate waited, and left meanwhile
            hub.unwatch(outbox, dropped)
            await hub.watch(outbox, names)
    finally:
        request.app[SOCKETS_KEY][0] -= 1
        request.app[OPEN_SOCKETS_KEY].discard(socket)
        hub.unwatch(outbox)
        sender.cancel()
        with contextlib.suppress(asyncio.CancelledError):
            await sender
    return socket


def _gone(request: web.Request) -> bool:
    """True when the page's connection is closed (what it sent before is still queued)."""
    return request.transport is None or request.transport.is_closing()


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
