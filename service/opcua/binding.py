"""OPC UA variables bound to CNC objects: read, subscribed and written through the
``Backend``, as the ADS front end reads, subscribes and writes them.

- Read: the variable's Value attribute has a read callback (asyncua's
  ``set_attribute_value_callback``): each Read calls the objects' getters (the ones ADS
  reads and the notification hub samples, ``Backend.direct_read``) on the event loop,
  from the kernel's newest snapshot, and turns the raw values into the OPC UA value
  (``sources.Source``).
- Subscribe: a monitored item on a bound variable adds one on-change subscription per
  source object to the ``NotificationHub``, at the item's sampling interval (asyncua
  revises it to the subscription's publishing interval; never faster than the kernel
  cycle: the hub's floor). Each sample goes to that monitored item alone; asyncua drops
  a value equal to the last one. The item's removal (or its session's end) deletes them.
  asyncua has no hook for "a monitored item was added": the variable's
  ``datachange_callbacks`` dict, where asyncua registers the item, tells us.
- Write: ``write`` checks the session's role (``roles.role_of``, the access policy
  of every front end: ``role_to_write``), the variant type and the range, then writes
  through ``Backend.decode_writes`` and ``apply_writes`` and answers when the kernel has
  applied it: BadUserAccessDenied, BadTypeMismatch, BadOutOfRange (the kernel's own
  refusal of a value included) and nothing changes.
"""

from __future__ import annotations

import asyncio
import logging
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from asyncua import Server, ua
from asyncua.crypto.permission_rules import User

from cnc_objects.objects import Entry
from cnc_objects.protocol.constants import TransmissionMode
from cnc_objects.protocol.errors import AdsReturnCode
from cnc_objects.protocol.roles import role_to_write

from ..backend import Backend
from .roles import role_of
from .sources import Source
from .values import bad, eu_information, good, source_time

log = logging.getLogger(__name__)

_S = ua.StatusCodes
_E = AdsReturnCode
#: The ADS code of a refused write -> the OPC UA status that answers it.
WRITE_STATUS: dict[int, int] = {
    _E.DEVICE_INVALIDDATA: _S.BadOutOfRange,
    _E.DEVICE_INVALIDPARM: _S.BadOutOfRange,
    _E.DEVICE_INVALIDSIZE: _S.BadTypeMismatch,
    _E.DEVICE_INVALIDACCESS: _S.BadNotWritable,
    _E.DEVICE_NOTREADY: _S.BadInvalidState,
    _E.DEVICE_INVALIDSTATE: _S.BadInvalidState,
}
_READ_ONLY = ua.AccessLevel.CurrentRead.mask
_READ_WRITE = ua.AccessLevel.CurrentRead.mask | ua.AccessLevel.CurrentWrite.mask
_VALUE = ua.AttributeIds.Value
DataChangeCallback = Callable[..., Any]  # asyncua's async (handle, DataValue) -> None


@dataclass(frozen=True, slots=True)
class _Watch:
    """The fields of an AddDeviceNotification the hub reads."""

    port: int
    group: int
    offset: int
    length: int
    transmission_mode: int = TransmissionMode.SERVER_ON_CHANGE


@dataclass
class Feed:
    """One variable's samples at one interval: a hub subscription per source object,
    shared by every monitored item of that interval (ten sessions that watch a variable
    cost one sample per pass, not ten), and those items: asyncua's handle -> callback."""

    hub_handles: list[int] = field(default_factory=list)
    items: dict[int, DataChangeCallback] = field(default_factory=dict)


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


class _Watched(dict[int, DataChangeCallback]):
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


class VariableBinder:
    """Binds OPC UA variables of ``server`` to the objects of ``backend``."""

    def __init__(self, server: Server, backend: Backend) -> None:
        self.server = server
        self.backend = backend
        self.variables: dict[ua.NodeId, BoundVariable] = {}
        self._aspace = server.iserver.aspace
        self._tasks: set[asyncio.Task[None]] = set()

    # ------------------------------------------------------------ binding

    async def bind(self, node_id: ua.NodeId, source: Source) -> BoundVariable:
        """Serve ``node_id``'s value from ``source``: its objects must exist
        (``KeyError`` names the one that does not); its access level says whether it may
        be written; its EngineeringUnits and EURange properties, where it has them, are
        set from ``source``."""
        space = self.backend.space
        entries = []
        for name in source.objects:
            entry = space.by_name(name)
            if entry is None or entry.read is None:
                raise KeyError(f"OPC UA variable {node_id.to_string()}: no readable object {name}")
            entries.append(entry)
        getters = tuple(self._getter(e) for e in entries)
        var = BoundVariable(node_id, source, tuple(entries), getters)
        self.variables[node_id] = var
        level = _READ_WRITE if source.write_object is not None else _READ_ONLY
        for attr in (ua.AttributeIds.AccessLevel, ua.AttributeIds.UserAccessLevel):
            await self._aspace.write_attribute_value(
                node_id, attr, ua.DataValue(ua.Variant(level, ua.VariantType.Byte)))
        await self._aspace.write_attribute_value(
            node_id, ua.AttributeIds.ValueRank,
            ua.DataValue(ua.Variant(1 if source.array else -1, ua.VariantType.Int32)))
        self._aspace.set_attribute_value_callback(node_id, _VALUE, lambda n, a: var.value())
        node = self._aspace[node_id]
        node.attributes[_VALUE].datachange_callbacks = _Watched(
            lambda handle, callback: self._item_added(var, handle, callback),
            lambda handle: self._item_removed(var, handle))
        await self._properties(node_id, source)
        return var

    def _getter(self, entry: Entry) -> Callable[[], Any]:
        """The getter ADS reads and the hub samples (``Backend.direct_read``), else a
        read through ``Backend.read_value`` decoded."""
        obj = entry.obj
        direct = self.backend.direct_read(obj.port, obj.group, obj.offset, obj.dtype.size)
        if direct is not None:
            return direct[0]
        read, dtype = self.backend.read_value, obj.dtype

        def through_backend() -> Any:
            code, data = read(obj.port, obj.group, obj.offset, dtype.size)
            if code:
                raise RuntimeError(f"{obj.name}: ADS code {code:#x}: {data!r}")
            return dtype.decode(data)

        return through_backend

    async def _properties(self, node_id: ua.NodeId, source: Source) -> None:
        """EngineeringUnits and EURange of an AnalogItem (added when the instance lacks
        them: both are optional or mandatory by type; we always give them)."""
        if source.unit is None:
            return
        node = self.server.get_node(node_id)
        idx = 0
        units = await _child(node, "EngineeringUnits")
        if units is None:
            units = await node.add_property(idx, "EngineeringUnits", eu_information(source.unit))
        else:
            await units.write_value(eu_information(source.unit))
        if source.limits is not None:
            low, high = source.limits
            eu_range = ua.Range(Low=low, High=high)
            found = await _child(node, "EURange")
            if found is None:
                await node.add_property(idx, "EURange", eu_range)
            else:
                await found.write_value(eu_range)

    # ------------------------------------------------------------ subscriptions

    def _item_added(self, var: BoundVariable, handle: int, callback: DataChangeCallback) -> None:
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
                _envelope(var, cycle_ns), _Watch(obj.port, obj.group, obj.offset, obj.dtype.size),
                cycle_ns, self._notifier(var, feed, k))
            if code:
                log.warning("OPC UA monitored item on %s: %s", var.node_id.to_string(), answer)
                self._send(callback, handle, [bad(_S.BadResourceUnavailable)])
                continue
            feed.hub_handles.append(answer)  # type: ignore[arg-type]

    def _item_removed(self, var: BoundVariable, handle: int) -> None:
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

    # ------------------------------------------------------------ writes

    async def write(self, node_id: ua.NodeId, value: ua.DataValue, user: User | None
                    ) -> ua.StatusCode:
        """Write ``value`` to a bound variable as the session of ``user`` may."""
        var = self.variables.get(node_id)
        if var is None or var.source.write_object is None or var.source.to_raw is None:
            return ua.StatusCode(_S.BadNotWritable)
        entry = self.backend.space.by_name(var.source.write_object)
        if entry is None or entry.write is None:
            return ua.StatusCode(_S.BadNotWritable)
        obj = entry.obj
        role = role_of(user)
        if role is not None and not role.may(role_to_write(obj.port, obj.group)):
            return ua.StatusCode(_S.BadUserAccessDenied)
        variant = value.Value
        if variant is None or variant.VariantType != var.source.variant:
            return ua.StatusCode(_S.BadTypeMismatch)
        try:
            data = obj.dtype.encode(var.source.to_raw(variant.Value))
        except (ValueError, OverflowError):
            return ua.StatusCode(_S.BadOutOfRange)
        except TypeError:
            return ua.StatusCode(_S.BadTypeMismatch)
        code, message, items = self.backend.decode_writes(obj.port, obj.group, obj.offset, data)
        if code:
            log.debug("OPC UA write to %s refused: %s", obj.name, message)
            return ua.StatusCode(WRITE_STATUS.get(code, _S.BadInternalError))
        done: asyncio.Future[list[tuple[int, str]]] = asyncio.get_running_loop().create_future()
        self.backend.apply_writes(items, done.set_result, holder=("opcua", id(user)))
        results = await done
        for code, message in results:
            if code:
                log.debug("OPC UA write to %s refused: %s", obj.name, message)
                return ua.StatusCode(WRITE_STATUS.get(code, _S.BadInternalError))
        return ua.StatusCode(_S.Good)


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


async def _child(node: Any, name: str) -> Any:
    """The child of ``node`` browsed as ``name`` (any namespace), None without one."""
    for child in await node.get_children():
        if (await child.read_browse_name()).Name == name:
            return child
    return None
