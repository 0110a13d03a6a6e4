"""Alarms of the client (mixed into ``AsyncClient``): the active list, the history,
acknowledge, and the events as they come (docs/alarms.md).

    listed = await c.alarms()                    # active alarms, newest first
    await c.acknowledge_alarm(listed.active[0].sequence)
    await c.acknowledge_all_alarms()
    async for event in c.alarm_events():         # "raised", "acknowledged", "cleared"
        print(event)

Everything goes through the alarm objects (``alarm_active[k].*``, ``alarm_history[k].*``,
``alarm_changes_r``); events come from a subscription to ``alarm_changes_r``: at each
change the lists are read again and compared with what was seen before.
"""

from __future__ import annotations

from collections.abc import AsyncGenerator
from dataclasses import dataclass
from datetime import UTC, datetime
from typing import Any

from cnc_objects.protocol.alarm_values import AlarmClass, AlarmState, Severity, describe_alarm

from . import names
from .client_core import MixinBase

ACTIVE_SLOTS = 16  # alarm_active[1..16] (objects.catalog_alarms.ACTIVE_SLOTS)
_FIELDS = ("sequence", "id", "severity", "class", "channel", "state", "time",
           "kernel_time", "cycle", "text", "file", "line", "column")
#: what an event is called, by the state it brought
EVENT_OF_STATE = {AlarmState.ACTIVE: "raised", AlarmState.ACKNOWLEDGED: "acknowledged",
                  AlarmState.CLEARED: "cleared"}


def _severity(value: int) -> Severity | int:
    try:
        return Severity(value)
    except ValueError:
        return value


@dataclass(frozen=True, slots=True)
class AlarmInfo:
    """One alarm as the service shows it."""

    sequence: int  # names the alarm for acknowledge_alarm
    id: int  # ISG-style error id
    severity: Severity | int  # OPC UA 1..1000
    alarm_class: AlarmClass
    channel: int  # 0 = the platform
    state: AlarmState
    wall_ns: int  # wall clock when raised (ns since 1970)
    kernel_ns: int  # kernel time when raised
    cycle: int
    text: str
    file: str
    line: int
    column: int

    @classmethod
    def from_values(cls, v: dict[str, Any]) -> AlarmInfo:
        """From the fields of one slot (``sequence``, ``id``, ... as the objects name them)."""
        return cls(v["sequence"], v["id"], _severity(v["severity"]), AlarmClass(v["class"]),
                   v["channel"], AlarmState(v["state"]), v["time"], v["kernel_time"],
                   v["cycle"], v["text"], v["file"], v["line"], v["column"])

    @property
    def time(self) -> datetime:
        """When it was raised (UTC)."""
        return datetime.fromtimestamp(self.wall_ns / 1e9, tz=UTC)

    @property
    def where(self) -> str:
        """``file:line:column``, or empty when the alarm has no place in a program."""
        return f"{self.file}:{self.line}:{self.column}" if self.file else ""

    @property
    def severity_name(self) -> str:
        """``warning``, ``error``, ... (the number when it has no name)."""
        s = self.severity
        return s.name.lower() if isinstance(s, Severity) else str(s)

    def as_dict(self) -> dict[str, Any]:
        """The alarm as JSON-ready values (``cnc alarms --json``, the MQTT bridge)."""
        return {
            "sequence": self.sequence, "id": self.id, "severity": int(self.severity),
            "severity_name": self.severity_name, "class": self.alarm_class.name.lower(),
            "channel": self.channel, "state": self.state.name.lower(),
            "time": self.time.isoformat().replace("+00:00", "Z"),
            "kernel_time_s": self.kernel_ns / 1e9, "cycle": self.cycle, "text": self.text,
            "file": self.file, "line": self.line, "column": self.column,
        }

    def __str__(self) -> str:
        return describe_alarm(self.sequence, self.state.name.lower(), self.severity_name,
                              self.id, self.channel, self.where, self.text)


@dataclass(frozen=True, slots=True)
class AlarmList:
    """The alarms at one moment: the change counter, the active alarms (newest first,
    at most 16 of ``active_count``) and, when asked for, the history (newest first)."""

    changes: int
    active_count: int
    active: tuple[AlarmInfo, ...]
    history: tuple[AlarmInfo, ...] = ()


@dataclass(frozen=True, slots=True)
class AlarmEvent:
    """An alarm was raised, acknowledged or cleared."""

    kind: str  # "raised", "acknowledged", "cleared"
    alarm: AlarmInfo

    def __str__(self) -> str:
        return f"{self.kind}: {self.alarm}"


_CONSISTENT_READ_TRIES = 10  # reads of the lists while the alarms keep changing
_CLASS_VALUES = frozenset(int(c) for c in AlarmClass)
_STATE_VALUES = frozenset(int(s) for s in AlarmState)


class AlarmOps(MixinBase):
    """The client's alarm requests."""

    async def alarms(self, history: bool = False) -> AlarmList:
        """The active alarms (newest first); with ``history`` also the history.

        The lists take several reads: when the alarms changed meanwhile
        (``alarm_changes_r`` moved), they are read again, so every alarm returned is one
        the service listed whole."""
        for _ in range(_CONSISTENT_READ_TRIES):
            listed, consistent = await self._alarms_once(history)
            if consistent:
                break
        return listed

    async def _alarms_once(self, history: bool) -> tuple[AlarmList, bool]:
        counts = await self.read_many(
            [names.alarm_changes_r, names.alarm_active_count_r, names.alarm_history_count_r])
        active_n = min(counts[names.alarm_active_count_r], ACTIVE_SLOTS)
        history_n = counts[names.alarm_history_count_r] if history else 0
        wanted = [f"alarm_active[{k}].{f}" for k in range(1, active_n + 1) for f in _FIELDS]
        wanted += [f"alarm_history[{k}].{f}" for k in range(1, history_n + 1) for f in _FIELDS]
        values = await self.read_many([*wanted, names.alarm_changes_r]) if wanted else counts
        consistent = values[names.alarm_changes_r] == counts[names.alarm_changes_r]

        def slots(element: str, n: int) -> tuple[AlarmInfo, ...]:
            rows = ({f: values[f"{element}[{k}].{f}"] for f in _FIELDS} for k in range(1, n + 1))
            # a slot emptied or rewritten between two reads is left out (and read again)
            return tuple(AlarmInfo.from_values(v) for v in rows
                         if v["sequence"] and v["class"] in _CLASS_VALUES
                         and v["state"] in _STATE_VALUES)

        return AlarmList(counts[names.alarm_changes_r], counts[names.alarm_active_count_r],
                         slots("alarm_active", active_n),
                         slots("alarm_history", history_n)), consistent

    async def acknowledge_alarm(self, sequence: int) -> None:
        """Acknowledge the alarm numbered ``sequence`` (an error stays active until
        RESET, a warning is cleared); an unknown number raises ``AdsError`` 0x70C."""
        await self.write(names.alarm_acknowledge_w, sequence)

    async def acknowledge_all_alarms(self) -> None:
        """Acknowledge every active alarm."""
        await self.write(names.alarm_acknowledge_all_w, True)

    async def alarm_events(self) -> AsyncGenerator[AlarmEvent, None]:
        """The alarms' events from now on, in the order they happened per alarm:
        ``raised``, ``acknowledged``, ``cleared`` (an alarm raised and cleared between
        two reads gives both). Leaving the loop ends the subscription."""
        # what is there already, read before the subscription: an alarm raised while it
        # opens is then told at its first sample, not taken for an old one
        seen = seen_states(await self.alarms(history=True))
        async for _sample in self.subscribe(names.alarm_changes_r):
            for event in events_since(seen, await self.alarms(history=True)):
                yield event


def seen_states(listed: AlarmList) -> dict[int, AlarmState]:
    """The state of every alarm of ``listed`` (active and history), by sequence number:
    where ``events_since`` starts."""
    return {a.sequence: a.state for a in (*listed.history, *listed.active)}


def events_since(seen: dict[int, AlarmState], listed: AlarmList) -> list[AlarmEvent]:
    """The events that lead from ``seen`` to ``listed``, oldest alarm first; ``seen`` is
    brought up to date. A warning's acknowledge clears it: one event, ``cleared``."""
    now = {a.sequence: a for a in (*listed.history, *listed.active)}
    events = []
    for sequence in sorted(now):
        alarm = now[sequence]
        before = seen.get(sequence)
        for state in AlarmState:
            if (before is None or state > before) and state <= alarm.state:
                if state == AlarmState.ACKNOWLEDGED and alarm.state == AlarmState.CLEARED:
                    continue
                events.append(AlarmEvent(EVENT_OF_STATE[state], alarm))
        seen[sequence] = alarm.state
    return events
