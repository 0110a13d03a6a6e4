"""The WebSockets cnc-web has open, closed when it stops.

aiohttp's shutdown waits for every request handler to end, and a WebSocket's handler
ends only when its page closes it: a browser left open would hold cnc-web's Ctrl-C (and a
test's teardown) for the whole shutdown timeout. So each WebSocket registers here while
it is open, and ``close_open_sockets`` (an ``on_shutdown`` handler) closes them with 1001
"going away": the pages see cnc-web leave, a held jog key is released by its handler's
``finally`` before the service connection closes.
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator

from aiohttp import WSCloseCode, web

OPEN_SOCKETS_KEY: web.AppKey[set[web.WebSocketResponse]] = web.AppKey("open_sockets")
STOPPING_MESSAGE = b"cnc-web is stopping"


@contextlib.contextmanager
def registered(request: web.Request, socket: web.WebSocketResponse) -> Iterator[None]:
    """Keep ``socket`` in the app's open set while the ``with`` block runs."""
    sockets = request.app[OPEN_SOCKETS_KEY]
    sockets.add(socket)
    try:
        yield
    finally:
        sockets.discard(socket)


async def close_open_sockets(app: web.Application) -> None:
    """Close every open WebSocket: 1001 going away (``on_shutdown``)."""
    open_sockets: set[web.WebSocketResponse] = app[OPEN_SOCKETS_KEY]
    for socket in list(open_sockets):
        with contextlib.suppress(ConnectionError):
            await socket.close(code=WSCloseCode.GOING_AWAY, message=STOPPING_MESSAGE)
