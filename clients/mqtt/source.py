"""The service side of the bridge: keep the selected objects subscribed, feed the outbox.

One *session* is one ``AsyncClient`` connection: resolve the ``--objects`` and
``--writable`` globs with browse, subscribe to every selected object (on change, checked
every ``cycle_ms`` of kernel time), put each sample into the outbox, and probe the service.

ZeroMQ reconnects a lost connection by itself, but a restarted service has forgotten our
subscriptions and would never send another sample. So the probe reads
``cnc_kernel_time_r`` every ``probe_s``: no answer within the client timeout means the
service is gone, a kernel time smaller than the last one means it restarted. Either ends
the session; the next one (after a backoff) subscribes again, and its first samples
republish every current value.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
import math
from collections.abc import Callable

from .. import names
from ..client import AsyncClient
from ..errors import AdsConnectionError, AdsError, AdsTimeoutError
from ..object_info import ObjectInfo
from .alarms import AlarmFeed
from .config import BridgeConfig
from .outbox import OFFLINE, ONLINE, Outbox
from .retry import Backoff, session

log = logging.getLogger(__name__)

PROBE_OBJECT = names.cnc_kernel_time_r  # REAL64 s, never decreases while a service runs
# Subscriptions waiting for their first sample at once. The client's transport keeps the
# samples that overtake their AddNotification reply for at most 64 handles and drops the
# rest, so a larger burst would lose first samples (and those objects' values).
SUBSCRIBE_WINDOW = 32
_LOST = (AdsTimeoutError, AdsConnectionError)


class ServiceLost(Exception):
    """The service stopped answering, or restarted (its subscriptions are gone)."""


async def resolve(client: AsyncClient, patterns: tuple[str, ...], what: str) -> list[ObjectInfo]:
    """The objects matching any of ``patterns`` (browse globs), each once, in order."""
    found: dict[str, ObjectInfo] = {}
    results = await asyncio.gather(*(client.browse(p) for p in patterns))
    for pattern, infos in zip(patterns, results):
        if not infos:
            log.warning("%s pattern %r matches no object of %s", what, pattern, client.endpoint)
        for info in infos:
            found.setdefault(info.name, info)
    return list(found.values())


class ServiceSource:
    """Subscriptions on the service, kept alive across service restarts.

    ``client`` is the connected client while a session runs (for writes), else None;
    ``writable`` the lower-case names ``--writable`` resolved to in that session.
    """

    def __init__(self, config: BridgeConfig, outbox: Outbox,
                 alarms: AlarmFeed | None = None) -> None:
        self._config = config
        self._outbox = outbox
        self._alarms = alarms  # the alarms' messages (clients/mqtt/alarms.py)
        self.client: AsyncClient | None = None
        self.writable: frozenset[str] = frozenset()
        self.selected: list[ObjectInfo] = []
        self.sessions = 0  # sessions that got every first sample (1 + service reconnects)

    async def run(self) -> None:
        """Sessions, one after the other, with backoff between them; until cancelled."""
        backoff = Backoff(self._config.reconnect_initial_s, self._config.reconnect_max_s)
        while True:
            try:
                await self._session(backoff)
            except* (ServiceLost, AdsError) as group:
                log.warning("service %s: %s", self._config.endpoint, group.exceptions[0])
            await backoff.wait()

    async def _session(self, backoff: Backoff) -> None:
        async with contextlib.AsyncExitStack() as stack:
            client = await stack.enter_async_context(
                AsyncClient(self._config.endpoint, timeout_s=self._config.service_timeout_s,
                            key_file=self._config.key_file, server_key=self._config.server_key)
            )
            try:
                # On a stop the client is closed first: the subscriptions then end at once
                # instead of each waiting for its DeleteNotification (up to the timeout when
                # the service is gone). The service forgets a vanished client's
                # notifications by itself.
                await session(self._serve(client, stack, backoff), "cnc-mqtt service session",
                              before_cancel=stack.aclose)
            finally:
                self.client = None
                self._outbox.set_status(OFFLINE)

    async def _serve(
        self, client: AsyncClient, stack: contextlib.AsyncExitStack, backoff: Backoff
    ) -> None:
        selected = [
            info for info in await resolve(client, self._config.objects, "--objects")
            if "r" in info.access  # a write-only object has nothing to publish
        ]
        writable = await resolve(client, self._config.writable, "--writable")
        self.selected = selected
        self.writable = frozenset(info.name.lower() for info in writable)
        self.client = client
        waiting = {info.name for info in selected}
        all_first = asyncio.Event()

        def first_sample_of(name: str) -> None:
            waiting.discard(name)
            if not waiting:
                all_first.set()

        if not waiting:
            all_first.set()
        window = asyncio.Semaphore(SUBSCRIBE_WINDOW)
        async with asyncio.TaskGroup() as tasks:
            for info in selected:
                tasks.create_task(
                    self._follow(client, info, window, first_sample_of), name=f"follow {info.name}"
                )
            tasks.create_task(self._probe(client, stack), name="probe service")
            if self._alarms is not None:
                tasks.create_task(self._follow_alarms(client), name="follow alarms")
            await all_first.wait()
            # The outbox holds every current value now; they go out before "online".
            self.sessions += 1
            backoff.reset()
            self._outbox.set_status(ONLINE)
            log.info("service %s: %d objects subscribed, %d writable",
                     self._config.endpoint, len(selected), len(writable))

    async def _follow(
        self,
        client: AsyncClient,
        info: ObjectInfo,
        window: asyncio.Semaphore,
        first_sample_of: Callable[[str], None],
    ) -> None:
        await window.acquire()
        in_window = True
        try:
            samples = client.subscribe(info.name, on_change=True, cycle_ms=self._config.cycle_ms)
            async with contextlib.aclosing(samples):
                async for sample in samples:
                    self._outbox.put(info, sample)
                    if in_window:
                        in_window = False
                        window.release()
                        first_sample_of(info.name)
        except _LOST:
            raise  # the session ends: reconnect
        except AdsError as exc:  # this object only (e.g. the service's handle limit)
            log.error("cannot follow %s: %s", info.name, exc)
            first_sample_of(info.name)
        finally:
            if in_window:
                window.release()

    async def _follow_alarms(self, client: AsyncClient) -> None:
        assert self._alarms is not None
        try:
            await self._alarms.follow(client)
        except _LOST:
            raise  # the session ends: reconnect
        except AdsError as exc:  # e.g. a service without alarm objects: values go on
            log.error("cannot follow the alarms: %s", exc)

    async def _probe(self, client: AsyncClient, stack: contextlib.AsyncExitStack) -> None:
        last_s = -math.inf
        while True:
            await asyncio.sleep(self._config.probe_s)  # the probe's period, not a wait for state
            try:
                kernel_time_s = await client.read(PROBE_OBJECT)
                lost = None if kernel_time_s >= last_s else "it restarted (kernel time went back)"
            except _LOST as exc:
                lost = str(exc)
            if lost:
                # Close the client first: every subscription then ends at once, instead of
                # each waiting for its DeleteNotification to time out.
                await stack.aclose()
                raise ServiceLost(lost)
            last_s = kernel_time_s
