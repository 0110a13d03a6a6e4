"""The catalog of alarms: the change counter, the active list, the history, and the two
acknowledge commands (docs/alarms.md).

ISG documents no alarm list objects (its HMI builds the list from the error messages,
docs/isg-notes.md 9.1); the names follow OPC 40502 ``CncAlarmType`` and ISG's error
message, the offsets are this project's ("project" in the description) and found by
name through the COM object directory. The list objects are platform objects: an alarm
names its channel. ``alarm_active[k]`` (k = 1 newest) shows the newest
``ACTIVE_SLOTS`` active alarms; ``alarm_history[k]`` the last ``alarm_history_max``
([limits]) raised.
"""

from __future__ import annotations

from enum import IntEnum

from cnc_objects.protocol.alarm_values import AlarmClass, AlarmState
from cnc_objects.protocol.constants import CncPort
from cnc_objects.protocol.datatypes import BOOLEAN, STRING, UNS16, UNS32, UNS64, DataType

from .addressing import GroupBase
from .model import Access
from .templates import CatalogSizes, ObjectTemplate, Scope

R, W = Access.READ, Access.WRITE
COM = CncPort.COM
COM_CH = GroupBase.COM_CHANNEL

ACTIVE_SLOTS = 16  # alarm_active[1..16]: the newest active alarms
ACTIVE_OFFSET, HISTORY_OFFSET, SLOT_STRIDE = 0x6100, 0x8000, 0x10

#: the fields of one alarm slot: (name, index in the slot, type, unit, meaning, values)
ALARM_FIELDS: tuple[tuple[str, int, DataType, str, str, type[IntEnum] | None], ...] = (
    ("sequence", 0, UNS32, "-",
     "sequence number (from 1) that names the alarm for an acknowledge; 0 = empty slot",
     None),
    ("id", 1, UNS32, "-", "ISG-style error id (OPC 40502 AlarmIdentifier)", None),
    ("severity", 2, UNS16, "-",
     "OPC UA severity: 500 warning, 800 error (RESET clears), 1000 fatal (restart)", None),
    ("class", 3, UNS16, "-", "which part raised it: 1 decoder, 2 path, 3 axis, 4 syntax "
     "check, 5 service, 6 kernel", AlarmClass),
    ("channel", 4, UNS16, "-", "logical channel id; 0 = the platform", None),
    ("state", 5, UNS16, "-", "1 active, 2 acknowledged (still active), 3 cleared",
     AlarmState),
    ("time", 6, UNS64, "ns", "wall clock when raised, ns since 1970-01-01 UTC", None),
    ("kernel_time", 7, UNS64, "ns", "kernel time when raised (cycles x cycle time)", None),
    ("cycle", 8, UNS64, "-", "GEO cycle it was raised in", None),
    ("text", 9, STRING(256), "-", "message (OPC Message)", None),
    ("file", 10, STRING(84), "-", "NC file of the place; empty = none", None),
    ("line", 11, UNS32, "-", "line in the file, from 1; 0 = none", None),
    ("column", 12, UNS32, "-", "column in the line, from 1; 0 = none", None),
)

ALARM_TEMPLATES: tuple[ObjectTemplate, ...] = (
    ObjectTemplate(
        "alarm_changes_r", Scope.PLATFORM, COM, COM_CH, 0x6000, UNS32, R, "-",
        "Counts every alarm raised, acknowledged or cleared: subscribe to it to follow the "
        "alarms (project)",
    ),
    ObjectTemplate(
        "alarm_active_count_r", Scope.PLATFORM, COM, COM_CH, 0x6001, UNS32, R, "-",
        "Active alarms (active or acknowledged, not cleared); the newest 16 are in "
        "alarm_active[k] (project)",
    ),
    ObjectTemplate(
        "alarm_history_count_r", Scope.PLATFORM, COM, COM_CH, 0x6002, UNS32, R, "-",
        "Alarms in the history, alarm_history[k] (at most limits.alarm_history_max) "
        "(project)",
    ),
    ObjectTemplate(
        "alarm_raised_r", Scope.PLATFORM, COM, COM_CH, 0x6003, UNS32, R, "-",
        "Alarms raised since the service started: the newest sequence number (project)",
    ),
    ObjectTemplate(
        "alarm_acknowledge_w", Scope.PLATFORM, COM, COM_CH, 0x6008, UNS32, W, "-",
        "Acknowledge the alarm with this sequence number (an error stays active until "
        "RESET, a warning is cleared); an unknown number: 0x70C (project)",
    ),
    ObjectTemplate(
        "alarm_acknowledge_all_w", Scope.PLATFORM, COM, COM_CH, 0x6009, BOOLEAN, W, "-",
        "TRUE acknowledges every active alarm (project)",
    ),
)


def active_element(k: int, field: str) -> str:
    """Element name of a field of the k-th newest active alarm: ``alarm_active[k].f``."""
    return f"alarm_active[{k}].{field}"


def history_element(k: int, field: str) -> str:
    """Element name of a field of the k-th newest alarm of the history."""
    return f"alarm_history[{k}].{field}"


def _slots(element: str, offset: int, count: int, what: str) -> tuple[ObjectTemplate, ...]:
    return tuple(
        ObjectTemplate(
            f"{element}[{k}].{name}", Scope.PLATFORM, COM, COM_CH,
            offset + SLOT_STRIDE * (k - 1) + n, dtype, R, unit,
            f"{what} {k} (1 = newest): {meaning} (project)", values,
        )
        for k in range(1, count + 1)
        for name, n, dtype, unit, meaning, values in ALARM_FIELDS
    )


def alarm_templates(sizes: CatalogSizes) -> tuple[ObjectTemplate, ...]:
    """Every alarm object: counters, commands, the active slots and ``alarm_history``
    history slots."""
    return (ALARM_TEMPLATES
            + _slots("alarm_active", ACTIVE_OFFSET, ACTIVE_SLOTS, "Active alarm")
            + _slots("alarm_history", HISTORY_OFFSET, sizes.alarm_history,
                     "Alarm of the history"))
