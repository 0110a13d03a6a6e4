"""The twin's alarms (``kernel.alarms``, read through the alarm objects) as OPC UA
Alarms & Conditions events: ``CncAlarmType`` (OPC 40502 6.10.2) from the Server object
and the CncInterface, ``AlertType`` (OPC 40501-1 9.1) from the MachineTool's
Notification/Messages.

- Each change of the alarms (``alarm_changes_r``, looked at every ``ALARM_POLL_S``
  on the loop) reads the alarm slots again; every alarm whose state moved gives one
  event per notifier: raised (ActiveState True, AckedState False), acknowledged (AckedState True),
  cleared (ActiveState False, Retain False: the condition ends).
- Fields: AlarmIdentifier / ErrorCode the ISG error id, Severity the alarm's (500
  warning, 800 error, 1000 fatal), Message its text and place, Time when raised,
  SourceNode/SourceName the channel's ChannelMonitoring node (the machine for platform
  alarms), ConditionId a node per active alarm under Messages (``Alarm<sequence>``),
  ConditionName ``Alarm<sequence>``.
- Acknowledge (AcknowledgeableConditionType, called on the ConditionId with the EventId)
  writes ``alarm_acknowledge_w``, the object ``cnc alarms ack`` writes, through the
  Backend under the same role rule: a monitor gets BadUserAccessDenied.
- ConditionRefresh / ConditionRefresh2 send RefreshStart, the newest event of every
  active alarm, RefreshEnd to the subscription that asks.
"""

from __future__ import annotations

import asyncio
import copy
import logging
import time
import uuid
from dataclasses import dataclass, replace
from datetime import UTC, datetime
from typing import Any

from asyncua import Node, Server, ua
from asyncua.common.events import get_event_obj_from_type_node

from cnc_objects.objects.catalog_alarms import ACTIVE_SLOTS, active_element, history_element
from cnc_objects.protocol.alarm_values import AlarmState
from cnc_objects.protocol.roles import role_to_write

from . import alarm_events_caller as caller
from .linked_backend import LinkedBackend
from .nodesets import CNC_URI, MACHINE_TOOL_URI
from .roles import role_of

log = logging.getLogger(__name__)

CNC_ALARM_TYPE, ALERT_TYPE = 1006, 39  # ns: CNC, MachineTool
_FIELDS = ("sequence", "id", "severity", "channel", "state", "time", "text", "file",
           "line", "column")
_S = ua.StatusCodes
_READ_TRIES = 10  # reads of the slots while the alarms keep changing
_ACKNOWLEDGE_OBJECT = "alarm_acknowledge_w"
#: how often (wall time) the loop looks at ``alarm_changes_r``. Not a subscription of the
#: notification hub: its due cycles are cycles the event-speed virtual clock must publish
#: (one each kernel cycle made a 120 s program take 3.4 s instead of 0.03 s), and with a
#: longer period an idle kernel (after an ERROR) never reaches the next due cycle
ALARM_POLL_S = 0.05


@dataclass(frozen=True, slots=True)
class AlarmRow:
    """One alarm as the slots show it."""

    sequence: int
    id: int
    severity: int
    channel: int
    state: AlarmState
    wall_ns: int
    text: str
    file: str
    line: int
    column: int

    @property
    def message(self) -> str:
        """The text, after its place in the program when it has one."""
        where = f"{self.file}:{self.line}:{self.column}: " if self.file else ""
        return where + self.text


class AlarmSlots:
    """Reads the alarm objects (active slots and history) through their getters."""

    def __init__(self, backend: LinkedBackend) -> None:
        space = backend.space
        self._backend = backend
        self._changes = _getter(backend, "alarm_changes_r")
        self._history_count = _getter(backend, "alarm_history_count_r")
        self._active = [{f: _getter(backend, active_element(k, f)) for f in _FIELDS}
                        for k in range(1, ACTIVE_SLOTS + 1)]
        self._history = []
        k = 1  # as many history slots as the catalog has ([limits] alarm_history_max)
        while space.by_name(history_element(k, "sequence")) is not None:
            self._history.append({f: _getter(backend, history_element(k, f))
                                  for f in _FIELDS})
            k += 1
        names = ["alarm_history_count_r", *(active_element(k, f) for k in
                 range(1, ACTIVE_SLOTS + 1) for f in _FIELDS),
                 *(history_element(k, f) for k in range(1, len(self._history) + 1)
                   for f in _FIELDS)]
        #: the objects a reading of the slots reads, fetched in one round trip
        self._slot_entries = [e for e in map(space.by_name, names) if e is not None]

    def changes(self) -> int:
        """``alarm_changes_r``: counts every raise, acknowledge and clear."""
        return int(self._changes())

    def read(self) -> dict[int, AlarmRow]:
        """Every alarm listed (active, then the history), by sequence number; read again
        when the alarms changed meanwhile."""
        rows: dict[int, AlarmRow] = {}
        for _ in range(_READ_TRIES):
            before = self._changes()
            with self._backend.prefetched(self._slot_entries):  # one round trip
                rows = self._rows()
            if self._changes() == before:
                break
        return rows

    def _rows(self) -> dict[int, AlarmRow]:
        rows: dict[int, AlarmRow] = {}
        for slot in [*self._history[:self._history_count()], *self._active]:
            v = {f: get() for f, get in slot.items()}
            if v["sequence"] and v["state"] in _STATES:
                rows[v["sequence"]] = AlarmRow(
                    v["sequence"], v["id"], v["severity"], v["channel"],
                    AlarmState(v["state"]), v["time"], v["text"], v["file"], v["line"],
                    v["column"])
        return rows


_STATES = frozenset(int(s) for s in AlarmState)


def _getter(backend: LinkedBackend, name: str) -> Any:
    entry = backend.space.by_name(name)
    if entry is None or entry.read is None:
        raise KeyError(f"no readable object {name}")
    return entry.read


class AlarmEvents:
    """The alarm events of one server (``build_alarm_events``)."""

    def __init__(self, server: Server, backend: LinkedBackend, machine: tuple[Node, str],
                 messages: Node, sources: dict[int, tuple[Node, str]]) -> None:
        self.server, self.backend = server, backend
        self.machine, self.messages, self.sources = machine, messages, sources
        self.slots = AlarmSlots(backend)
        self.seen: dict[int, AlarmState] = {}
        #: the newest events of every active alarm (one per notifier): ConditionRefresh
        self.latest: dict[int, list[Any]] = {}
        self.conditions: dict[ua.NodeId, int] = {}  # ConditionId -> sequence
        self.event_ids: dict[bytes, int] = {}  # EventId -> sequence (active alarms)
        self._templates: list[tuple[Any, ua.NodeId]] = []  # (event, notifier)
        self._refresh: list[Any] = []  # RefreshStart, RefreshEnd templates
        self._lock = asyncio.Lock()
        self._tasks: set[asyncio.Task[None]] = set()
        self._last_changes = 0
        self._poll_handle: asyncio.TimerHandle | None = None

    async def start(self) -> None:
        """Event templates, the condition methods, the first reading, the look every
        ``ALARM_POLL_S``."""
        server = self.server
        cnc = await server.get_namespace_index(CNC_URI)
        mt = await server.get_namespace_index(MACHINE_TOOL_URI)
        server_node = ua.NodeId(ua.ObjectIds.Server)
        notifiers = [(ua.NodeId(CNC_ALARM_TYPE, cnc), server_node, "AlarmIdentifier"),
                     (ua.NodeId(ALERT_TYPE, mt), self.messages.nodeid, "ErrorCode")]
        interface = await _cnc_interface(server, cnc)
        if interface is not None:  # CncInterfaceType GeneratesEvent CncAlarmType (40502)
            await interface.set_event_notifier([ua.EventNotifier.SubscribeToEvents])
            notifiers.append((ua.NodeId(CNC_ALARM_TYPE, cnc), interface.nodeid,
                              "AlarmIdentifier"))
        for type_id, notifier, identifier in notifiers:
            event = await get_event_obj_from_type_node(server.get_node(type_id))
            event.add_property("NodeId", None, ua.VariantType.NodeId)  # the ConditionId
            # a String (asyncua types a property the nodeset gives no value as Null)
            event.add_property(identifier, "", ua.VariantType.String)
            event.emitting_node = notifier
            self._templates.append((event, notifier))
        for type_id, text in ((ua.ObjectIds.RefreshStartEventType, "ConditionRefresh begins"),
                              (ua.ObjectIds.RefreshEndEventType, "ConditionRefresh ends")):
            event = await get_event_obj_from_type_node(server.get_node(ua.NodeId(type_id)))
            event.SourceNode, event.SourceName = server_node, "Server"
            event.Message = ua.LocalizedText(text)
            event.Severity = 1
            self._refresh.append(event)
        await self.messages.set_event_notifier([ua.EventNotifier.SubscribeToEvents])
        caller.install(server.iserver)
        isession = server.iserver.isession
        isession.add_method_callback(
            ua.NodeId(ua.ObjectIds.AcknowledgeableConditionType_Acknowledge), self.acknowledge)
        for method in (ua.ObjectIds.ConditionType_ConditionRefresh,
                       ua.ObjectIds.ConditionType_ConditionRefresh2):
            isession.add_method_callback(ua.NodeId(method), self.refresh)
        await self._update(emit=False)
        self._last_changes = self.slots.changes()
        self._poll_handle = asyncio.get_running_loop().call_later(ALARM_POLL_S, self._poll)

    # ------------------------------------------------------------ following the alarms

    def _poll(self) -> None:
        """(loop, every ``ALARM_POLL_S``) Read the alarms again when their change
        counter moved."""
        self._poll_handle = asyncio.get_running_loop().call_later(ALARM_POLL_S, self._poll)
        changes = self.slots.changes()
        if changes == self._last_changes:
            return
        self._last_changes = changes
        task = asyncio.get_running_loop().create_task(self._update_logged())
        self._tasks.add(task)
        task.add_done_callback(self._tasks.discard)

    async def _update_logged(self) -> None:
        """``_update`` on a change: a fault is logged, the service goes on (the next
        change reads the alarms again)."""
        try:
            await self._update(emit=True)
        except Exception:
            log.exception("OPC UA alarm events: reading the alarms failed")

    async def _update(self, emit: bool) -> None:
        """Read the alarms; an event for every alarm whose state moved."""
        async with self._lock:
            rows = self.slots.read()
            for sequence in sorted(rows):
                row = rows[sequence]
                if self.seen.get(sequence) == row.state:
                    continue
                if sequence not in self.seen and row.state == AlarmState.CLEARED and emit:
                    self.seen[sequence] = row.state  # raised and cleared unseen: both
                    await self._emit(replace(row, state=AlarmState.ACTIVE))
                self.seen[sequence] = row.state
                if emit or row.state != AlarmState.CLEARED:
                    await self._emit(row, trigger=emit)
            # a cleared alarm that left the history is done with (the rest stay: an
            # active one may be beyond the 16 active slots and the history for a while)
            self.seen = {s: state for s, state in self.seen.items()
                         if s in rows or state != AlarmState.CLEARED}

    async def _emit(self, row: AlarmRow, trigger: bool = True) -> None:
        condition = await self._condition(row)
        events = [self._event(template, notifier, row, condition)
                  for template, notifier in self._templates]
        for event in events:
            self.event_ids[event.EventId.Value] = row.sequence
        if row.state == AlarmState.CLEARED:
            self.latest.pop(row.sequence, None)
            self.event_ids = {e: s for e, s in self.event_ids.items() if s != row.sequence}
        else:
            self.latest[row.sequence] = events
        if trigger:
            service = self.server.iserver.subscription_service
            for event in events:
                await service.trigger_event(event)
        if row.state == AlarmState.CLEARED:
            self.conditions.pop(condition, None)
            self._forget(condition)

    def _forget(self, condition: ua.NodeId) -> None:
        """Delete the condition node of a cleared alarm. Only Messages refers to it:
        that reference goes, then the node, without asyncua's search of every node for
        references to it (a RESET may clear a hundred alarms at once)."""
        iserver = self.server.iserver
        parent = iserver.aspace[self.messages.nodeid]
        parent.references[:] = [r for r in parent.references if r.NodeId != condition]
        [status] = iserver.node_mgt_service.delete_nodes(ua.DeleteNodesParameters(
            NodesToDelete=[ua.DeleteNodesItem(NodeId=condition, DeleteTargetReferences=False)]))
        status.check()

    async def _condition(self, row: AlarmRow) -> ua.NodeId:
        """The ConditionId of ``row``: a node under Messages while the alarm is active."""
        for node_id, sequence in self.conditions.items():
            if sequence == row.sequence:
                return node_id
        node = await self.messages.add_object(self.messages.nodeid.NamespaceIndex,
                                              f"Alarm{row.sequence}")
        self.conditions[node.nodeid] = row.sequence
        return node.nodeid

    def _event(self, template: Any, notifier: ua.NodeId, row: AlarmRow,
               condition: ua.NodeId) -> Any:
        event = copy.copy(template)
        source, name = self.sources.get(row.channel, self.machine)
        active = row.state != AlarmState.CLEARED
        acked = row.state != AlarmState.ACTIVE
        # Time: when it happened (raised: when the kernel raised it; else now)
        _stamp(event, datetime.fromtimestamp(row.wall_ns / 1e9, tz=UTC)
               if row.state == AlarmState.ACTIVE else datetime.now(UTC))
        event.emitting_node = notifier
        event.SourceNode = source.nodeid
        event.SourceName = name
        event.Message = ua.LocalizedText(row.message)
        event.Severity = row.severity
        event.NodeId = condition
        event.ConditionName = f"Alarm{row.sequence}"
        event.BranchId = ua.NodeId()
        event.Retain = active
        event.EnabledState = ua.LocalizedText("Enabled")
        setattr(event, "EnabledState/Id", True)
        event.ActiveState = ua.LocalizedText("Active" if active else "Inactive")
        setattr(event, "ActiveState/Id", active)
        event.AckedState = ua.LocalizedText("Acknowledged" if acked else "Unacknowledged")
        setattr(event, "AckedState/Id", acked)
        event.Quality = ua.StatusCode(_S.Good)
        event.LastSeverity = row.severity
        for identifier in ("AlarmIdentifier", "ErrorCode"):  # CncAlarmType, AlertType
            if identifier in event.data_types:
                setattr(event, identifier, str(row.id))
        return event

    # ------------------------------------------------------------ methods

    async def acknowledge(self, parent: ua.NodeId, *args: ua.Variant) -> ua.StatusCode:
        """Acknowledge(EventId, Comment) on a ConditionId: ``alarm_acknowledge_w``."""
        sequence = self.conditions.get(parent)
        if sequence is None:
            return ua.StatusCode(_S.BadNodeIdUnknown)  # no (longer an) active alarm
        if len(args) != 2 or not isinstance(args[0].Value, bytes):
            return ua.StatusCode(_S.BadArgumentsMissing if len(args) < 2
                                 else _S.BadInvalidArgument)
        if self.event_ids.get(args[0].Value) != sequence:
            return ua.StatusCode(_S.BadEventIdUnknown)
        entry = self.backend.space.by_name(_ACKNOWLEDGE_OBJECT)
        assert entry is not None and entry.write is not None  # the catalog has it
        obj = entry.obj
        role = role_of(caller.calling_user())
        if role is not None and not role.may(role_to_write(obj.port, obj.group)):
            return ua.StatusCode(_S.BadUserAccessDenied)
        if self.seen.get(sequence) != AlarmState.ACTIVE:
            return ua.StatusCode(_S.BadConditionBranchAlreadyAcked)
        code, message, items = self.backend.decode_writes(
            obj.port, obj.group, obj.offset, obj.dtype.encode(sequence))
        if not code:
            done: asyncio.Future[list[tuple[int, str]]] = (
                asyncio.get_running_loop().create_future())
            self.backend.apply_writes(items, done.set_result, holder=("opcua-alarms", sequence))
            code, message = next((r for r in await done if r[0]), (0, ""))
        if code:
            log.debug("OPC UA acknowledge of alarm %d refused: %s", sequence, message)
            return ua.StatusCode(_S.BadInvalidState)
        return ua.StatusCode(_S.Good)

    async def refresh(self, parent: ua.NodeId, *args: ua.Variant) -> ua.StatusCode:
        """ConditionRefresh(SubscriptionId) and ConditionRefresh2(SubscriptionId,
        MonitoredItemId): RefreshStart, the active alarms' newest events, RefreshEnd, to
        that subscription's (or that item's) event items only."""
        if not args or not isinstance(args[0].Value, int):
            return ua.StatusCode(_S.BadArgumentsMissing if not args else _S.BadInvalidArgument)
        subscription = self.server.iserver.subscription_service.subscriptions.get(
            args[0].Value)
        if subscription is None:
            return ua.StatusCode(_S.BadSubscriptionIdInvalid)
        items = subscription.monitored_item_srv
        item = args[1].Value if len(args) > 1 else None
        if item is not None and item not in items._monitored_items:
            return ua.StatusCode(_S.BadMonitoredItemIdInvalid)
        start, end = self._refresh
        async with self._lock:
            for _, notifier in self._templates:
                await _send(items, _refresh_event(start, notifier), item)
            for sequence in sorted(self.latest):
                for event in self.latest[sequence]:
                    await _send(items, event, item)
            for _, notifier in self._templates:
                await _send(items, _refresh_event(end, notifier), item)
        return ua.StatusCode(_S.Good)

    def close(self) -> None:
        """Stop following the alarms."""
        if self._poll_handle is not None:
            self._poll_handle.cancel()
            self._poll_handle = None


def _stamp(event: Any, when: datetime) -> None:
    """A new EventId, Time ``when``, ReceiveTime now (as asyncua's EventGenerator)."""
    event.EventId = ua.Variant(uuid.uuid4().bytes, ua.VariantType.ByteString)
    event.Time = when
    event.ReceiveTime = datetime.now(UTC)
    local = ua.TimeZoneDataType()
    local.Offset = time.localtime(when.timestamp()).tm_gmtoff // 60
    event.LocalTime = local


async def _send(items: Any, event: Any, item: int | None) -> None:
    """``event`` to a subscription's event items on its notifier (``items``: asyncua's
    MonitoredItemService), or to its item ``item`` alone when that one watches it
    (asyncua's own ``trigger_event(event, mid)`` does not ask)."""
    if item is None:
        await items.trigger_event(event)
    elif item in items._monitored_events.get(event.emitting_node, ()):
        await items.trigger_event(event, item)


def _refresh_event(template: Any, notifier: ua.NodeId) -> Any:
    event = copy.copy(template)
    _stamp(event, datetime.now(UTC))
    event.emitting_node = notifier
    return event


async def _cnc_interface(server: Server, cnc: int) -> Node | None:
    """Objects/CncInterface (``cnc_interface``), None when the server has none."""
    for node in await server.nodes.objects.get_children():
        if (await node.read_browse_name()) == ua.QualifiedName("CncInterface", cnc):
            return node
    return None


async def build_alarm_events(server: Server, backend: LinkedBackend, machine: Node
                             ) -> AlarmEvents:
    """The alarm events of ``server`` for the MachineTool ``machine`` (its
    Notification/Messages and Monitoring/Channel<c> nodes), started."""
    mt = await server.get_namespace_index(MACHINE_TOOL_URI)
    messages = await machine.get_child([f"{mt}:Notification", f"{mt}:Messages"])
    monitoring = await machine.get_child(f"{mt}:Monitoring")
    sources: dict[int, tuple[Node, str]] = {}
    for channel in backend.kernel.config.channels:
        name = f"Channel{channel.id}"
        sources[channel.id] = (await monitoring.get_child(f"{mt}:{name}"), name)
    events = AlarmEvents(server, backend, (machine, backend.kernel.config.name), messages,
                         sources)
    await events.start()
    return events
