"""Binds the alarm objects (``objects.catalog_alarms``) to the kernel's alarm log.

Reads come from the log's ``view`` (replaced whole on every change, so a read never sees
half a list); the acknowledge writes become ``AcknowledgeAlarm`` /
``AcknowledgeAllAlarms`` commands, applied by the cycle thread; an unknown sequence
number is refused with a sentence (ADS 0x70C on the wire).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from cnc_objects.objects import CncObject
from cnc_objects.objects.catalog_alarms import (
    ACTIVE_SLOTS,
    ALARM_FIELDS,
    active_element,
    history_element,
)
from cnc_objects.objects.templates import CatalogSizes

from .binding_types import AreaBinding, Binder, Getter, WriteBinder
from .kernel.alarms import Alarm, AlarmView
from .kernel.commands import AcknowledgeAlarm, AcknowledgeAllAlarms
from .kernel.kernel import Kernel

#: what each field of a slot reads from an alarm
_FIELD_VALUE: dict[str, Callable[[Alarm], Any]] = {
    "sequence": lambda a: a.sequence,
    "id": lambda a: a.id,
    "severity": lambda a: int(a.severity),
    "class": lambda a: int(a.alarm_class),
    "channel": lambda a: a.channel,
    "state": lambda a: int(a.state),
    "time": lambda a: a.wall_ns,
    "kernel_time": lambda a: a.kernel_ns,
    "cycle": lambda a: a.cycle,
    "text": lambda a: a.text,
    "file": lambda a: a.file,
    "line": lambda a: a.line,
    "column": lambda a: a.column,
}


def _view(value: Callable[[AlarmView], Any]) -> Binder:
    def bind(kernel: Kernel, obj: CncObject) -> Getter:
        alarms = kernel.alarms
        return lambda: value(alarms.view)

    return bind


def _slot(alarms_of: Callable[[AlarmView], tuple[Alarm, ...]], k: int, field: str) -> Binder:
    """Field ``field`` of the k-th alarm (1 = newest) of a list; the type's zero when
    the list is shorter (the object decodes it from its own bytes)."""
    read = _FIELD_VALUE[field]

    def bind(kernel: Kernel, obj: CncObject) -> Getter:
        alarms, empty = kernel.alarms, obj.dtype.decode(bytes(obj.dtype.size))

        def get() -> Any:
            listed = alarms_of(alarms.view)
            return read(listed[k - 1]) if k <= len(listed) else empty

        return get

    return bind


def alarm_readers(sizes: CatalogSizes) -> dict[str, Binder]:
    """Readers of every alarm object (``sizes.alarm_history`` history slots)."""
    readers: dict[str, Binder] = {
        "alarm_changes_r": _view(lambda v: v.changes & 0xFFFFFFFF),
        "alarm_active_count_r": _view(lambda v: len(v.active)),
        "alarm_history_count_r": _view(lambda v: len(v.history)),
        "alarm_raised_r": _view(lambda v: v.raised),
    }
    for name, *_ in ALARM_FIELDS:
        for k in range(1, ACTIVE_SLOTS + 1):
            readers[active_element(k, name)] = _slot(lambda v: v.active, k, name)
        for k in range(1, sizes.alarm_history + 1):
            readers[history_element(k, name)] = _slot(lambda v: v.history, k, name)
    return readers


ALARM_WRITERS: dict[str, WriteBinder] = {
    "alarm_acknowledge_w": lambda kernel, obj: AcknowledgeAlarm,
    "alarm_acknowledge_all_w": lambda kernel, obj: AcknowledgeAllAlarms,
}


#: alarms, as many history slots as the log keeps (``objects.catalog_alarms``)
BINDING = AreaBinding(alarm_readers, lambda sizes: ALARM_WRITERS)
