"""Subscriptions of bound variables: the monitored items of one variable and sampling
interval share one feed, an on-change subscription per source object at the
``NotificationHub``, sampled in kernel time (never faster than the kernel cycle). Every
sample goes to each item of the feed, in order; asyncua drops a value equal to the last.

asyncua has no hook for "a monitored item was added": the variable's
``datachange_callbacks`` dict, where asyncua registers each item's callback, is replaced
by ``WatchedCallbacks``, which tells ``Feeds`` when an item comes and goes.

``BoundVariable`` (a variable, the objects behind it, its feeds) lives here, where its
subscriptions are kept; ``binding`` makes them.
"""

from __future__ import annotations

import asyncio
import logging
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from asyncua import ua

from cnc_objects.objects import Entry

from .link_frames import HubWatch
from .linked_backend import LinkedBackend
from .sources import Source
from .values import bad, good, source_time

log = logging.getLogger(__name__)

_S = ua.StatusCodes
DataChangeCallback = Callable[..., Any]  # asyncua's async (handle, DataValue) -> None


@dataclass
class Feed:
    """One variable's samples at one interval: a hub subscription per source object,
    shared by every monitored item of that interval (ten sessions that watch a variable
    cost one sample per pass, not ten), and those items: asyncua's handle -> callback."""

    hub_handles: list[int] = field(default_factory=list)
    items: dict[int, DataChangeCallback] = field(default_factory=dict)


class WatchedCallbacks(dict[int, DataChangeCallback]):
    """asyncua's datachange callbacks of one attribute, telling us of items added and
    removed (asyncua sets ``[handle] = callback`` and ``pop(handle)``)."""

    def __init__(self, added: Callable[[int, DataChangeCallback], None],
                 removed: Callable[[int], None]) -> None:
        super().__init__()
        self._added, self._removed = added, removed

    def __setitem__(self, handle: int, callback: DataChangeCallback) -> None:
        super().__setitem__(handle, callback)
        self._added(handle, callback)

    def pop(self, handle: int, *default: Any) -> Any:
        found = handle in self
        value = super().pop(handle, *default)
        if found:
            self._removed(handle)
        return value


@dataclass
class BoundVariable:
    """A variable and the objects behind it."""

    node_id: ua.NodeId
    source: Source
    entries: tuple[Entry, ...]
    getters: tuple[Callable[[], Any], ...]
    #: the hub subscriptions by sampling interval (ns), each shared by the monitored
    #: items of that interval; and the interval of each item by asyncua's handle
    feeds: dict[int, Feed] = field(default_factory=dict)
    items: dict[int, int] = field(default_factory=dict)
    #: the raw values last read and their DataValue: a read of unchanged objects answers
    #: it again (no new DataValue; its SourceTimestamp says when the value last changed)
    _last_raw: Any = None
    _last: ua.DataValue | None = None

    def value(self) -> ua.DataValue:
        """The current value, Good; BadInternalError when a getter fails."""
        getters = self.getters
        try:
            if len(getters) == 1:  # the common case: one object
                raw = getters[0]()
                if raw == self._last_raw and self._last is not None:
                    return self._last
                value = good(self.source.value(raw), self.source.variant)
                self._last_raw, self._last = raw, value
                return value
            raw = tuple([get() for get in getters])
            if raw == self._last_raw and self._last is not None:
                return self._last
            value = good(self.source.value(*raw), self.source.variant)
        except Exception:  # a getter fault must not take the service down
            log.exception("reading OPC UA variable %s failed", self.node_id.to_string())
            return bad(_S.BadInternalError)
        self._last_raw, self._last = raw, value
        return value


class Feeds:
    """The feeds of every bound variable of one server, over ``backend``'s hub."""

    def __init__(self, backend: LinkedBackend) -> None:
        self.backend = backend
        self._tasks: set[asyncio.Task[None]] = set()

    def watch(self, var: BoundVariable) -> WatchedCallbacks:
        """The datachange callbacks dict to give ``var``'s Value attribute."""
        return WatchedCallbacks(lambda handle, callback: self.added(var, handle, callback),
                                lambda handle: self.removed(var, handle))

    def added(self, var: BoundVariable, handle: int, callback: DataChangeCallback) -> None:
        """A monitored item on ``var``: it joins the feed of its revised sampling interval,
        made on first use (one hub subscription per source object). asyncua reads the
        item's first value itself."""
        cycle_ns = int(_sampling_interval_ms(callback) * 1e6)
        var.items[handle] = cycle_ns
        feed = var.feeds.get(cycle_ns)
        if feed is not None:
            feed.items[handle] = callback
            return
        feed = var.feeds[cycle_ns] = Feed(items={handle: callback})
        hub = self.backend.hub
        for k, entry in enumerate(var.entries):
            obj = entry.obj
            code, answer = hub.add(
                _envelope(var, cycle_ns), HubWatch(obj.port, obj.group, obj.offset, obj.dtype.size),
                cycle_ns, self._notifier(var, feed, k))
            if code:
                log.warning("OPC UA monitored item on %s: %s", var.node_id.to_string(), answer)
                self._send(callback, handle, [bad(_S.BadResourceUnavailable)])
                continue
            feed.hub_handles.append(answer)  # type: ignore[arg-type]

    def removed(self, var: BoundVariable, handle: int) -> None:
        """The item leaves its feed; the last one out ends the feed's hub subscriptions."""
        cycle_ns = var.items.pop(handle, None)
        feed = var.feeds.get(cycle_ns) if cycle_ns is not None else None
        if feed is None:
            return
        feed.items.pop(handle, None)
        if feed.items:
            return
        del var.feeds[cycle_ns]  # type: ignore[arg-type]
        for hub_handle in feed.hub_handles:
            self.backend.hub.delete(_envelope(var, cycle_ns), hub_handle)  # type: ignore[arg-type]

    def _notifier(self, var: BoundVariable, feed: Feed, k: int) -> Callable[..., bool]:
        """The hub's ``notify`` for source object ``k`` of ``var`` in ``feed``: the
        samples made DataValues once, handed to every item of the feed."""
        single = len(var.entries) == 1
        dtype = var.entries[k].obj.dtype
        source = var.source

        def notify(envelope: Any, port: int, samples: list[list[Any]]) -> bool:
            if not feed.items:
                return True
            values: list[ua.DataValue] = []
            if single:  # every sample of the batch, in order (a batch spans passes)
                for _, _, filetime, data in samples:
                    try:
                        values.append(good(source.value(dtype.decode(data)), source.variant,
                                           source_time(filetime)))
                    except Exception:
                        log.exception("OPC UA sample of %s failed", var.node_id.to_string())
                        values.append(bad(_S.BadInternalError))
            else:  # one of several objects changed: the value from all of them, now
                values.append(var.value())
            for handle, callback in list(feed.items.items()):
                self._send(callback, handle, values)
            return True

        return notify

    def _send(self, callback: DataChangeCallback, handle: int, values: list[ua.DataValue]
              ) -> None:
        """Hand ``values`` to asyncua's monitored item, in order. asyncua's callback is a
        coroutine that only queues the value (with a publishing interval it never waits):
        it is run here to its end, without a task per sample (2 000 items at 100 ms
        made 20 000 tasks a second, and the cycle waited for the GIL: make bench, part
        opcua, jitter). One that does wait is finished by a task, in order."""
        for k, value in enumerate(values):
            coroutine = callback(handle, value)
            try:
                waits_for = coroutine.send(None)
            except StopIteration:
                continue
            except Exception:
                log.exception("OPC UA monitored item %d: queueing a value failed", handle)
                continue
            task = asyncio.get_running_loop().create_task(
                self._finish(coroutine, waits_for, callback, handle, values[k + 1:]))
            self._tasks.add(task)
            task.add_done_callback(self._tasks.discard)
            return

    async def _finish(self, coroutine: Any, waits_for: Any, callback: DataChangeCallback,
                      handle: int, rest: list[ua.DataValue]) -> None:
        """Drive ``coroutine`` on from where it waits (as a task would), then the rest."""
        while True:
            if waits_for is None:
                await asyncio.sleep(0)
            else:
                await asyncio.wait([waits_for])
            try:
                waits_for = coroutine.send(None)
            except StopIteration:
                break
        for value in rest:
            await callback(handle, value)


def _envelope(var: BoundVariable, cycle_ns: int) -> tuple[Any, ...]:
    """The hub's envelope of a feed: its first part, the client the hub's limits count,
    is the variable (its feeds are at most one per interval and source object)."""
    return ("opcua", id(var)), cycle_ns


def _sampling_interval_ms(callback: DataChangeCallback) -> float:
    """The sampling interval asyncua revised the item to: its subscription's publishing
    interval (asyncua answers ``RevisedSamplingInterval`` with it); 0 when unknown (the
    hub then samples every kernel cycle)."""
    service = getattr(callback, "__self__", None)
    try:
        return float(service.isub.data.RevisedPublishingInterval)  # type: ignore[union-attr]
    except AttributeError:
        return 0.0
