"""Continuous jog from a browser, held by a dead-man WebSocket (``/ws/jog``).

cnc-web reaches the service through one connection for all browsers, so the service
cannot tell which browser pressed a jog key: cnc-web keeps that itself. A browser opens
``/ws/jog?csrf=TOKEN`` (the write role, as any jog) and sends

    {"press": {"channel": 1, "axis": 2, "direction": 1, "rapid": false}}
    {"renew": true}            every RENEW_S while the key is held
    {"release": true}          key-up, pointer-up, window blur, page hidden

The socket holds the keys it pressed. They are released (the jog object written FALSE)
on ``release``, when the socket closes for any reason (the page closed or reloaded, the
network lost, the session ended: ``Access.end`` closes its connections), and when no
renewal came for ``HOLD_TIMEOUT_S`` (a page that hangs with its socket open). Each
renewal writes the key TRUE again, which renews the service's own hold as well. Every
message is answered ``{"held": [...]}`` or ``{"error": sentence}``.
"""

from __future__ import annotations

import asyncio
import contextlib
import json
import logging
from dataclasses import dataclass
from typing import Any

from aiohttp import WSMsgType, web

from cnc_objects.clients.client import AsyncClient
from cnc_objects.clients.errors import AdsError, ClientValueError

from .. import names
from .access import require_write
from .closing import registered

log = logging.getLogger(__name__)

HOLD_TIMEOUT_S = 1.0  # wall time without a renewal after which a held key is released
RENEW_S = 0.25  # how often the page renews (sent to the page with the first answer)
MANUAL_MODE = 4  # ChannelMode.MANUAL
JOG_CONTINUOUS = 2  # ManualOperationMode: continuous jog


@dataclass(frozen=True)
class Key:
    """One jog key of one axis: the object that is TRUE while it is held."""

    channel: int
    axis: int
    direction: int  # +1 or -1

    @property
    def name(self) -> str:
        """The jog key's object."""
        side = "plus" if self.direction > 0 else "minus"
        return f"ch{self.channel}.ax{self.axis}.manual_jog_{side}_w"

    @classmethod
    def parse(cls, data: Any) -> Key:
        """The key a ``press`` names; ``ValueError`` says what is wrong."""
        if not isinstance(data, dict):
            raise ValueError("'press' is {channel, axis, direction, rapid}")
        fields: list[Any] = [data.get(n) for n in ("channel", "axis", "direction")]
        if not all(isinstance(v, int) and not isinstance(v, bool) for v in fields):
            raise ValueError("'press' needs whole numbers channel, axis and direction")
        channel, axis, direction = fields
        if channel < 1 or axis < 1 or direction not in (1, -1):
            raise ValueError("channel and axis count from 1; direction is 1 or -1")
        return cls(channel, axis, direction)


async def press(client: AsyncClient, key: Key, rapid: bool) -> None:
    """Press ``key`` in continuous jog (MANUAL selected first, as ``cnc jog`` does)."""
    if await client.read(names.ch(key.channel).mc_active_mode_r) != MANUAL_MODE:
        await client.write(names.ch(key.channel).mc_command_mode_w, MANUAL_MODE)
    prefix = f"ch{key.channel}.ax{key.axis}"
    await client.write(f"{prefix}.manual_operation_mode_w", JOG_CONTINUOUS)
    await client.write(f"{prefix}.manual_rapid_w", rapid)
    await client.write(key.name, True)


async def release(client: AsyncClient, keys: set[Key]) -> None:
    """Write every key of ``keys`` FALSE (each tried, whatever the others answer)."""
    for key in list(keys):
        try:
            await client.write(key.name, False)
        except (AdsError, ClientValueError) as exc:  # the service still answered: logged
            log.warning("release of %s refused: %s", key.name, exc)
    keys.clear()


class Holder:
    """The keys one socket holds, and when they were last renewed."""

    def __init__(self, client: AsyncClient) -> None:
        self.client = client
        self.keys: set[Key] = set()

    async def handle(self, message: Any) -> dict[str, Any]:
        """Act on one message of the page; the answer to send."""
        if not isinstance(message, dict):
            return {"error": "not a jog message"}
        try:
            if "press" in message:
                key = Key.parse(message["press"])
                rapid = bool(message["press"].get("rapid", False))
                self.keys.add(key)  # before the write: a release meanwhile finds it
                await press(self.client, key, rapid)
            elif "renew" in message:
                for key in self.keys:
                    await self.client.write(key.name, True)
            elif "release" in message:
                await release(self.client, self.keys)
            else:
                return {"error": "send press, renew or release"}
        except ValueError as exc:
            return {"error": str(exc)}
        except (AdsError, ClientValueError) as exc:
            await self.release()
            return {"error": str(exc)}
        return {"held": sorted(k.name for k in self.keys)}

    async def release(self) -> None:
        """Release every key held (shielded: a cancelled handler still releases)."""
        if self.keys:
            await asyncio.shield(release(self.client, self.keys))


async def jog_socket(request: web.Request, client: AsyncClient) -> web.StreamResponse:
    """The dead-man WebSocket (see the module docstring)."""
    require_write(request, "jog continuously", token=request.query.get("csrf", ""))
    socket = web.WebSocketResponse(heartbeat=5.0)
    await socket.prepare(request)
    holder = Holder(client)
    try:
        with registered(request, socket):  # cnc-web's shutdown closes it (closing.py)
            await socket.send_json({"held": [], "renew_s": RENEW_S})
            await _serve(socket, holder)
    except ConnectionError:
        pass  # the page went: its keys are released below
    finally:
        await holder.release()
        with contextlib.suppress(ConnectionError):
            await socket.close()
    return socket


async def _serve(socket: web.WebSocketResponse, holder: Holder) -> None:
    """Answer the page's messages until its socket closes."""
    while True:
        try:
            message = await socket.receive(timeout=HOLD_TIMEOUT_S if holder.keys else None)
        except TimeoutError:
            log.info("jog keys released: no renewal for %.1f s", HOLD_TIMEOUT_S)
            await holder.release()
            await socket.send_json({"held": [], "error": "jog released: the page did not "
                                    f"renew it for {HOLD_TIMEOUT_S:g} s"})
            continue
        if message.type != WSMsgType.TEXT:
            return  # closed, closing or failed
        try:
            data = json.loads(message.data)
        except ValueError:
            data = None
        await socket.send_json(await holder.handle(data))
