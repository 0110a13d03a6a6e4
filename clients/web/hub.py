"""Live values for every browser: one subscription per object, fanned out to all sessions.

A browser's WebSocket watches object names; the hub subscribes to an object when its
first watcher comes and ends the subscription when its last watcher goes, so ten open
pages cost the service what one costs. Each watcher has an ``Outbox`` that keeps only
the newest value of each object: a slow browser gets fewer, newer values, never a queue
that grows, and the sender flushes it at most every ``FLUSH_S`` (a frame rate the eye
cannot beat, well above the 20 Hz a moving position needs).

What a page, a session and all pages may watch is bounded (``budgets.WatchBudgets``):
a name over a budget, and a name the service does not have, is refused to that page
only. Subscribe requests go out at most ``subscribes_in_flight`` at a time and
unsubscribes one at a time, after ``linger_s`` (a page that watches the name again
meanwhile gets it free), so pages that watch and unwatch in a loop cannot queue
thousands of requests ahead of an operator's RESET.
"""

from __future__ import annotations

import asyncio
import logging
import math
from collections import Counter
from collections.abc import AsyncGenerator
from typing import Any

from cnc_objects.clients.client import AsyncClient, Sample
from cnc_objects.clients.errors import AdsConnectionError, AdsError, AdsTimeoutError
from cnc_objects.protocol.errors import AdsReturnCode

from .. import names
from .budgets import WatchBudgets

log = logging.getLogger(__name__)

NAMES_PER_TURN = 100  # names of one message handled before others get the loop (~0.5 ms)
FLUSH_S = 0.015  # at most ~66 messages a second to one browser
SUBSCRIPTION_CYCLE_MS = 20  # the service checks a watched object every 20 ms of kernel time (50 Hz)
RESUBSCRIBE_S = 1.0  # wall time before a subscription lost with the service is tried again
HEARTBEAT_S = 1.0  # wall time between two checks that the subscriptions are alive
HEARTBEAT_OBJECT = names.cnc_tick_counter_r  # changes every cycle: a sure beat
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
    """The values waiting for one browser (one WebSocket of ``session``): the newest of
    each object, and refusals; ``names``: what it watches."""

    def __init__(self, session: str = "") -> None:
        self.session = session
        self.names: set[str] = set()
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

    def __init__(self, client: AsyncClient, cycle_ms: int = SUBSCRIPTION_CYCLE_MS,
                 budgets: WatchBudgets | None = None) -> None:
        self._client = client
        self._cycle_ms = cycle_ms
        self.budgets = budgets if budgets is not None else WatchBudgets()
        self._watchers: dict[str, set[Outbox]] = {}
        self._sessions: dict[str, Counter[str]] = {}  # session -> name -> its pages watching
        self._latest: dict[str, Any] = {}
        self._tasks: dict[str, asyncio.Task[None]] = {}  # subscribed, lingering ones too
        self._leaving: dict[str, float] = {}  # name nobody watches -> since (loop time)
        self._left = asyncio.Event()  # a name was added to ``_leaving``
        self._setups = asyncio.Semaphore(self.budgets.subscribes_in_flight)
        self.samples_received = 0  # from the service, for the benchmark
        self.service_lost = False  # the heartbeat's view: the service stopped answering
        self._heartbeat = asyncio.create_task(self._watch_service(), name="web heartbeat")
        self._reaper = asyncio.create_task(self._reap(), name="web unsubscriber")

    @property
    def subscriptions(self) -> int:
        """How many objects the hub subscribes to at the service now."""
        return len(self._tasks)

    async def watch(self, outbox: Outbox, names: list[str]) -> None:
        """Send ``outbox`` every value of ``names`` (the current one first); a name the
        service does not have, or over a budget, is refused in ``outbox``'s errors."""
        unreadable: str | None = None  # the catalogue could not be read: why
        for count, name in enumerate(dict.fromkeys(names), 1):
            if count % NAMES_PER_TURN == 0:
                await asyncio.sleep(0)  # let other pages and requests in between
            if name in outbox.names:
                continue
            try:
                refused = unreadable or await self._refusal(outbox, name)
            except AdsError as exc:  # the service did not give its catalogue: once is enough
                refused = unreadable = str(exc)
            if refused is not None:
                outbox.refuse(name, refused)
                continue
            outbox.names.add(name)
            self._sessions.setdefault(outbox.session, Counter())[name] += 1
            self._watchers.setdefault(name, set()).add(outbox)
            self._leaving.pop(name, None)  # watched again while it lingered: free
            if name in self._latest:
                outbox.put(name, self._latest[name])
            if name not in self._tasks:
                self._tasks[name] = asyncio.create_task(self._follow(name), name=f"web {name}")

    async def _refusal(self, outbox: Outbox, name: str) -> str | None:
        """Why ``outbox`` may not watch ``name`` now, or None. Unknown names are looked up
        in the client's catalogue, without a search for the nearest names: a page may
        send thousands."""
        if name not in self._tasks and await self._client.find(name) is None:
            return str(AdsError(AdsReturnCode.DEVICE_SYMBOLNOTFOUND, f"no object {name!r}"))
        budgets = self.budgets
        if len(outbox.names) >= budgets.names_per_page:
            return budgets.refusal("names_per_page")
        session = self._sessions.get(outbox.session, Counter())
        if name not in session and len(session) >= budgets.names_per_session:
            return budgets.refusal("names_per_session")
        if name not in self._tasks and len(self._tasks) >= budgets.names_total:
            if not self._drop_oldest_leaving():
                return budgets.refusal("names_total")
        return None

    def _drop_oldest_leaving(self) -> bool:
        """End the subscription nobody watched for longest, to make room; False when
        every subscription is watched."""
        if not self._leaving:
            return False
        name = next(iter(self._leaving))
        del self._leaving[name]
        self._latest.pop(name, None)
        task = self._tasks.pop(name, None)
        if task is not None:
            task.cancel()
        return True

    def unwatch(self, outbox: Outbox, names: list[str] | None = None) -> None:
        """Stop sending ``names`` (all when None) to ``outbox``; an object nobody watches
        any more is unsubscribed after ``linger_s``."""
        loop = asyncio.get_running_loop()
        session = self._sessions.get(outbox.session)
        for name in list(outbox.names) if names is None else names:
            if name not in outbox.names:
                continue
            outbox.names.discard(name)
            if session is not None:
                session[name] -= 1
                if session[name] <= 0:
                    del session[name]
            watchers = self._watchers.get(name)
            if watchers is None:
                continue
            watchers.discard(outbox)
            if not watchers:
                del self._watchers[name]
                if name in self._tasks:
                    self._leaving[name] = loop.time()
                    self._left.set()
        if session is not None and not session:
            del self._sessions[outbox.session]

    async def _reap(self) -> None:
        """Delete the subscriptions nobody watched for ``linger_s``, one at a time (each
        delete is a request to the service; one at a time leaves room for the others)."""
        loop = asyncio.get_running_loop()
        while True:
            if not self._leaving:
                self._left.clear()
                await self._left.wait()
                continue
            name, since = next(iter(self._leaving.items()))  # the oldest: insertion order
            wait_s = since + self.budgets.linger_s - loop.time()
            if wait_s > 0:
                await asyncio.sleep(wait_s)
                continue
            del self._leaving[name]
            self._latest.pop(name, None)
            task = self._tasks.pop(name, None)
            if task is not None:
                task.cancel()
                await asyncio.gather(task, return_exceptions=True)

    async def close(self) -> None:
        """End every subscription."""
        tasks = [self._heartbeat, self._reaper, *self._tasks.values()]
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
            samples = self._client.subscribe(name, cycle_ms=self._cycle_ms)
            try:
                async with self._setups:  # at most subscribes_in_flight requests out
                    self._take(name, await _first_sample(samples))
                async for sample in samples:
                    self._take(name, sample)
            except (AdsTimeoutError, AdsConnectionError) as exc:  # the service is gone: retry
                log.info("subscription of %s lost: %s", name, exc)
            except AdsError as exc:  # e.g. over the service's limit: say so to its watchers
                for outbox in self._watchers.get(name, ()):
                    outbox.refuse(name, str(exc))
                if self._tasks.get(name) is asyncio.current_task():
                    del self._tasks[name]
                return
            await asyncio.sleep(RESUBSCRIBE_S)

    def _take(self, name: str, sample: Sample) -> None:
        value = json_value(sample.value)
        self.samples_received += 1
        self._latest[name] = value
        for outbox in self._watchers.get(name, ()):
            outbox.put(name, value)


async def _first_sample(samples: AsyncGenerator[Sample, None]) -> Sample:
    """The first sample of a subscription. Cancelled meanwhile (the page let go), the
    subscribe request is already on its way: its answer is awaited and the subscription
    it made deleted, so that no notification is left behind at the service."""
    step = asyncio.ensure_future(samples.__anext__())
    try:
        return await asyncio.shield(step)
    except asyncio.CancelledError:
        await asyncio.wait([step])
        if not step.cancelled() and step.exception() is None:
            await samples.aclose()
        raise


def _forget(task: asyncio.Task[Any]) -> None:
    """Retrieve the end of a subscription left behind (its delete may fail: the service
    that held it is gone), so that asyncio does not log it as never retrieved."""
    if not task.cancelled():
        task.exception()
