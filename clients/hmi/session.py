"""The connection to the service: connect, discover, subscribe, watch, retry — forever.

One session is one ``AsyncClient``: the machine is discovered, every shown object gets a
subscription of its own (a task in one TaskGroup), and a heartbeat read notices a
service that stopped answering (a subscription alone cannot: it just stays silent).
Then the client is closed, which ends every subscription at once, and after
``RETRY_S`` a new session starts: subscriptions of a restarted service are new ones.
"""

from __future__ import annotations

import asyncio
import inspect
import logging
from collections.abc import Awaitable, Callable, Sequence
from dataclasses import dataclass
from typing import Any, NoReturn, Protocol

from cnc_objects.clients.client import AsyncClient, DeviceInfo
from cnc_objects.clients.errors import (
    AdsConnectionError,
    AdsError,
    AdsTimeoutError,
    AuthenticationError,
)
from cnc_objects.clients.units import engineering

from .. import names
from . import text
from .machine import Machine, discover

log = logging.getLogger(__name__)

RETRY_S = 1.0  # wall time between two connection attempts
HEARTBEAT_S = 1.0  # wall time between two liveness reads while connected
HEARTBEAT_OBJECT = names.cnc_tick_counter_r  # any readable object will do; this one is tiny

_LOST = (AdsTimeoutError, AdsConnectionError)  # the service does not answer


@dataclass(frozen=True, slots=True)
class Feed:
    """One subscription: ``apply`` gets each value of ``name`` (it may be a coroutine
    function: the next sample waits until it is done). ``cycle_ms``: how often the
    service checks for a change, in kernel time (None: the client's default, 10 ms). ``engineering``:
    ``apply`` gets the value in engineering units (mm, mm/min, %), by the scale the
    service gives for the object (clients/units.py), not the object's own value."""

    name: str
    apply: Callable[[Any], Awaitable[None] | None]
    cycle_ms: int | None = None
    engineering: bool = False


class SessionListener(Protocol):
    """What the HMI is told about the connection."""

    def session_started(
        self, client: AsyncClient, machine: Machine, info: DeviceInfo
    ) -> Sequence[Feed]:
        """Connected and discovered: show the machine; return the feeds to follow."""

    def session_lost(self, reason: str) -> None:
        """The service stopped answering (or never did); a retry follows."""

    def feed_failed(self, feed: Feed, exc: AdsError) -> None:
        """The service refused one subscription; the others go on."""

    def service_replied(self) -> None:
        """A reply came (heartbeat, sample): the service was alive just now."""


async def run_sessions(
    endpoint: str, timeout_s: float, listener: SessionListener,
    key_file: str | None = None, server_key: str | None = None,
) -> NoReturn:
    """Keep a session with the service at ``endpoint`` open, reconnecting for ever
    (``key_file``, ``server_key``: CURVE keys for a service with ``--keys``)."""
    while True:
        client = AsyncClient(endpoint, timeout_s=timeout_s, key_file=key_file,
                             server_key=server_key)
        await client.__aenter__()
        try:
            info = await client.info()
            listener.service_replied()
            machine = await discover(client)
            feeds = listener.session_started(client, machine, info)
            async with asyncio.TaskGroup() as group:
                for feed in feeds:
                    group.create_task(_follow(client, feed, listener), name=f"feed {feed.name}")
                group.create_task(_heartbeat(client, listener), name="heartbeat")
        except* _LOST as lost:
            reason = lost.exceptions[0]
            log.info("session with %s lost: %s", endpoint, reason)
            refused = isinstance(reason, AuthenticationError)  # its key: say so, not "unreachable"
            listener.session_lost(f"{reason} — retrying" if refused else text.unreachable(endpoint))
        except* AdsError as refused:  # it answers, but not as an HMI needs: say so, retry
            listener.session_lost(
                f"service at {endpoint} refused the HMI: {refused.exceptions[0]} — retrying"
            )
        finally:
            await client.__aexit__(None, None, None)  # ends every subscription at once
        await asyncio.sleep(RETRY_S)


async def _follow(client: AsyncClient, feed: Feed, listener: SessionListener) -> None:
    try:
        info = await client.describe(feed.name) if feed.engineering else None
        async for sample in client.subscribe(feed.name, cycle_ms=feed.cycle_ms):
            listener.service_replied()
            result = feed.apply(sample.value if info is None else engineering(info, sample.value))
            if inspect.isawaitable(result):
                await result
    except _LOST:
        raise
    except AdsError as exc:  # e.g. an object this service does not have: show the rest
        listener.feed_failed(feed, exc)


async def _heartbeat(client: AsyncClient, listener: SessionListener) -> None:
    while True:
        await asyncio.sleep(HEARTBEAT_S)
        try:
            await client.read(HEARTBEAT_OBJECT)
            listener.service_replied()
        except _LOST:
            # Close before the TaskGroup cancels the feeds: a closed client ends them at
            # once, instead of each waiting a timeout to delete its notification.
            await client.__aexit__(None, None, None)
            raise
