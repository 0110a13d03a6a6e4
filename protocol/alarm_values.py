"""What the numbers of the alarm objects mean (``alarm_active[k].state``, ``.class``,
``.severity``): the value sets of the one alarm model (docs/alarms.md), shared by the
kernel, the catalog and every client, as ``values`` is for the channel's objects."""

from __future__ import annotations

from enum import IntEnum


class AlarmState(IntEnum):
    """Where an alarm is in its life (OPC UA ActiveState and AckedState in one)."""

    ACTIVE = 1  # raised; nobody acknowledged it yet
    ACKNOWLEDGED = 2  # still active (an error holds its channel until RESET); seen
    CLEARED = 3  # no longer active: RESET, an acknowledged warning, or pushed out


class AlarmClass(IntEnum):
    """Which part of the CNC raised the alarm (ISG's "BF type", the function block)."""

    DECODER = 1  # the NC program as decoded: syntax, expressions, control flow (2xxxx)
    PATH = 2  # path preparation and interpolation: geometry, limits, compensation (5xxxx)
    AXIS = 3  # axes: clones, jog of path, manual mode, software limits in jog (7xxxx)
    CHECK = 4  # a finding of a syntax check (SYNCHK run, cnc check)
    SERVICE = 5  # the service around the kernel: the output area's limits and writes
    KERNEL = 6  # the kernel itself: the cycle task failed


def describe_alarm(sequence: int, state: str, severity: str, alarm_id: int, channel: int,
                   where: str, text: str) -> str:
    """One line for an alarm, the same in the kernel's log and in every client:
    ``#7 active error 20008 ch1: MDI:1:4: <text>`` (``where``: ``file:line:column`` or "")."""
    place = f"{where}: " if where else ""
    return f"#{sequence} {state} {severity} {alarm_id} ch{channel}: {place}{text}"


class Severity(IntEnum):
    """OPC 40502 severities: lowest 1, highest 1000 (its example of three levels)."""

    INFO = 1  # information only
    WARNING = 500  # ISG remedy class 0: the program goes on
    ERROR = 800  # ISG remedy class 2/5: the channel stops; RESET clears it
    FATAL = 1000  # ISG remedy class 6/7: restart (the kernel's RESET) clears it
