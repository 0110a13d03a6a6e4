"""Live values for every browser: one subscription per object, fanned out to all sessions.

A browser's WebSocket watches object names; the hub subscribes to an object when its
first watcher comes and ends the subscription when its last watcher goes, so ten open
pages cost the service what one costs. Each watcher has an ``Outbox`` that keeps only
the newest value of each object: a slow browser gets fewer, newer values, never a queue
that grows, and the sender flushes it at most every ``FLUSH_S`` (a frame rate the eye
cannot beat, well above the 20 Hz a moving position needs).
"""

from __future__ import annotations

import asyncio
import logging
import math
from typing import Any

from cnc_objects.clients.client import AsyncClient
from cnc_objects.clients.errors import AdsConnectionError, AdsError, AdsTimeoutError

log = logging.getLogger(__name__)

FLUSH_S = 0.015  # at most ~66 messages a second to one browser
SUBSCRIPTION_CYCLE_MS = 20  # the service checks a watched object every 20 ms of kernel time (50 Hz)
RESUBSCRIBE_S = 1.0  # wall time before a subscription lost with the service is tried again
HEARTBEAT_S = 1.0  # wall time between two checks that the subscriptions are alive
HEARTBEAT_OBJECT = "cnc_tick_counter_r"  # changes every cycle: a sure beat
BEAT_CYCLE_MS = 500  # one beat per 0.5 s of kernel time
STALE_S = 3.0  # wall time without a beat after which the subscriptions count as gone


def json_value(value: Any) -> Any:
    """``value`` as JSON can carry it: bytes as hex, NaN and infinities as strings."""
    if isinstance(value, bytes | bytearray):
        return value.hex()
    if isinstance(value, float) and not math.isfinite(value):
        return str(value)
    if isinstance(value, list | tuple):
        return [json_value(v) for v in value]
    if isinstance(value, dict):
        return {str(k): json_value(v) for k, v in value.items()}
    return value


class Outbox:
    """The values waiting for one browser: the newest of each object, and refusals."""

    def __init__(self) -> None:
        self.values: dict[str, Any] = {}
        self.errors: dict[str, str] = {}
        self.ready = asyncio.Event()

    def put(self, name: str, value: Any) -> None:
        """Keep ``value`` as the newest of ``name`` (an older unsent one is dropped)."""
        self.values[name] = value
        self.ready.set()

    def refuse(self, name: str, message: str) -> None:
        """Tell the browser that ``name`` cannot be watched, in the service's words."""
        self.errors[name] = message
        self.ready.set()

    def take(self) -> dict[str, Any]:
        """The message to send now (and empty the box)."""
        message: dict[str, Any] = {}
        if self.values:
            message["values"], self.values = self.values, {}
        if self.errors:
            message["errors"], self.errors = self.errors, {}
        self.ready.clear()
        return message


class LiveHub:
    """The subscriptions of all browsers, over one client of the service."""

    def __init__(self, client: AsyncClient, cycle_ms: int = SUBSCRIPTION_CYCLE_MS) -> None:
        self._client = client
        self._cycle_ms = cycle_ms
        self._watchers: dict[str, set[Outbox]] = {}
        self._latest: dict[str, Any] = {}
        self._tasks: dict[str, asyncio.Task[None]] = {}
        self.samples_received = 0  # from the service, for the benchmark
        self.service_lost = False  # the heartbeat's view: the service stopped answering
        self._heartbeat = asyncio.create_task(self._watch_service(), name="web heartbeat")

    @property
    def subscriptions(self) -> int:
        """How many objects the hub subscribes to at the service now."""
        return len(self._tasks)

    def watch(self, outbox: Outbox, names: list[str]) -> None:
        """Send ``outbox`` every value of ``names`` (the current one first)."""
        for name in names:
            watchers = self._watchers.setdefault(name, set())
            watchers.add(outbox)
            if name in self._latest:
                outbox.put(name, self._latest[name])
            if name not in self._tasks:
                self._tasks[name] = asyncio.create_task(self._follow(name), name=f"web {name}")

    def unwatch(self, outbox: Outbox, names: list[str] | None = None) -> None:
        """Stop sending ``names`` (all when None) to ``outbox``; an object nobody watches
        any more is unsubscribed."""
        for name in list(self._watchers) if names is None else names:
            watchers = self._watchers.get(name)
            if watchers is None:
                continue
            watchers.discard(outbox)
            if not watchers:
                del self._watchers[name]
                self._latest.pop(name, None)
                task = self._tasks.pop(name, None)
                if task is not None:
                    task.cancel()

    async def close(self) -> None:
        """End every subscription."""
        self._heartbeat.cancel()
        tasks = [self._heartbeat, *self._tasks.values()]
        self._tasks.clear()
        for task in tasks:
            task.cancel()
        await asyncio.gather(*tasks, return_exceptions=True)

    async def _watch_service(self) -> None:
        """Notice subscriptions that went silent: the service stopped, or restarted (its
        subscriptions are gone, though reads work again at once). A subscription of its
        own to the tick counter beats every ``BEAT_CYCLE_MS`` of kernel time; when no beat
        came for ``STALE_S``, everything watched is subscribed anew."""
        loop = asyncio.get_running_loop()
        beat_at = [loop.time()]

        async def beat() -> None:
            async for _ in self._client.subscribe(HEARTBEAT_OBJECT, cycle_ms=BEAT_CYCLE_MS):
                beat_at[0] = loop.time()

        beating = asyncio.create_task(beat(), name="web heartbeat subscription")
        try:
            while True:
                await asyncio.sleep(HEARTBEAT_S)
                if loop.time() - beat_at[0] < STALE_S:
                    continue
                self.service_lost = True
                try:
                    await self._client.read(HEARTBEAT_OBJECT)  # answers: subscribe anew
                except (AdsTimeoutError, AdsConnectionError):
                    continue
                log.warning("subscriptions went silent: subscribing anew to %d objects",
                            len(self._tasks))
                self.service_lost = False
                beat_at[0] = loop.time()
                for task in (beating, *self._tasks.values()):
                    task.cancel()
                    task.add_done_callback(_forget)
                beating = asyncio.create_task(beat(), name="web heartbeat subscription")
                for name in list(self._tasks):
                    self._tasks[name] = asyncio.create_task(self._follow(name), name=f"web {name}")
        finally:
            beating.cancel()

    async def _follow(self, name: str) -> None:
        while True:
            try:
                async for sample in self._client.subscribe(name, cycle_ms=self._cycle_ms):
                    value = json_value(sample.value)
                    self.samples_received += 1
                    self._latest[name] = value
                    for outbox in self._watchers.get(name, ()):
                        outbox.put(name, value)
            except (AdsTimeoutError, AdsConnectionError) as exc:  # the service is gone: retry
                log.info("subscription of %s lost: %s", name, exc)
            except AdsError as exc:  # e.g. no such object: say so to its watchers, once
                for outbox in self._watchers.get(name, ()):
                    outbox.refuse(name, str(exc))
                self._tasks.pop(name, None)
                return
            await asyncio.sleep(RESUBSCRIBE_S)


def _forget(task: asyncio.Task[Any]) -> None:
    """Retrieve the end of a subscription left behind (its delete may fail: the service
    that held it is gone), so that asyncio does not log it as never retrieved."""
    if not task.cancelled():
        task.exception()
