"""Alarms: every error and warning of the kernel, its decoders, its syntax checks and the
service's output area, as one model (OPC 40502 ``CncAlarmType``, ISG's error message).

An alarm has the ISG error id, a severity (OPC UA 1..1000), a class (which part raised
it), the channel, its time stamps (wall clock, kernel time and cycle), the text, the
place in the NC program, and a state. Its sequence number (from 1, never reused while
the service runs) names it for an acknowledge.

States (``AlarmState``), as a table of what moves them (docs/alarms.md):

=============  ======================  =======================================
state          acknowledge             RESET of its channel
=============  ======================  =======================================
ACTIVE         error: ACKNOWLEDGED;    CLEARED (not the restart kinds: KERNEL,
               warning: CLEARED        axis configuration)
ACKNOWLEDGED   (stays)                 CLEARED
CLEARED        (stays)                 (stays)
=============  ======================  =======================================

One alarm per fault: a fault (id, channel, place in the program) that is already active
raises no second alarm; reported again more gravely (a syntax check's warning, then the
run's error), the new alarm replaces the old one, which is CLEARED (issue 36).

A warning needs no RESET (ISG: "internal remedy, no action"), so its acknowledge clears
it; an error holds the channel until RESET, as ISG's remedy class 2/5 says. The active
list holds ACTIVE and ACKNOWLEDGED alarms; the history the last ``history_max`` alarms
raised, in any state. Published as an immutable ``AlarmView`` after every change, so
that readers on other threads never see a half-made list. No sockets, no addresses.
"""

from __future__ import annotations

import logging
import time
from collections import deque
from dataclasses import dataclass, replace
from typing import Protocol

from cnc_objects.protocol.alarm_values import AlarmClass as AlarmClass
from cnc_objects.protocol.alarm_values import AlarmState as AlarmState
from cnc_objects.protocol.alarm_values import Severity as Severity
from cnc_objects.protocol.alarm_values import describe_alarm

from .axis_params import AxisErrorId
from .nc.errors import NcErrorId
from .refusal import Refusal, RefusalReason


class ErrorLike(Protocol):
    """What an alarm is raised from: ``state.ErrorEntry`` (state holds the log, so the
    log names the entry by its fields, without importing it back)."""

    @property
    def id(self) -> int:
        """ISG-style error id."""

    @property
    def text(self) -> str:
        """The message."""

    @property
    def file(self) -> str:
        """NC file of the place; empty = none."""

    @property
    def line(self) -> int:
        """Line of the place, from 1."""

    @property
    def column(self) -> int:
        """Column of the place, from 1."""

    @property
    def warning(self) -> bool:
        """A warning: the channel goes on."""

log = logging.getLogger(__name__)

ALARM_HISTORY_MAX = 32  # [limits] alarm_history_max: 13 objects each
ALARM_ACTIVE_MAX = 100  # [limits] alarm_active_max


#: error ids that only a restart (the kernel's RESET) clears: the axis configuration
RESTART_IDS = frozenset({AxisErrorId.CLONE_MASTER_MISSING, AxisErrorId.CLONE_NOT_CREATED,
                         AxisErrorId.CLONE_LIMITS_INCONSISTENT})
#: NC error ids that the service's output area causes
SERVICE_IDS = frozenset({NcErrorId.OUTPUT_LIMIT_REACHED, NcErrorId.FILE_WRITE_FAILED})
#: the id of a failed cycle task (project id)
KERNEL_FAULT_ID = 90001

_CLASS_BY_THOUSANDS: tuple[tuple[range, AlarmClass], ...] = (
    (range(20000, 30000), AlarmClass.DECODER),
    (range(50000, 60000), AlarmClass.PATH),
    (range(70000, 80000), AlarmClass.AXIS),
    (range(90000, 100000), AlarmClass.KERNEL),
)


def class_of(error_id: int) -> AlarmClass:
    """The class an error id belongs to, by ISG's id ranges (a table, docs/alarms.md)."""
    if error_id in SERVICE_IDS:
        return AlarmClass.SERVICE
    if error_id in RESTART_IDS:  # 50462 too: a clone of the axis configuration
        return AlarmClass.AXIS
    for ids, alarm_class in _CLASS_BY_THOUSANDS:
        if error_id in ids:
            return alarm_class
    return AlarmClass.DECODER


@dataclass(frozen=True, slots=True)
class Alarm:
    """One alarm, as the objects, the clients and the gateways show it."""

    sequence: int  # from 1; names the alarm for an acknowledge
    id: int  # ISG-style error id (OPC AlarmIdentifier)
    severity: Severity
    alarm_class: AlarmClass
    channel: int  # logical channel id; 0 = the platform
    wall_ns: int  # time.time_ns() when raised
    kernel_ns: int  # kernel time when raised (cycles x cycle time)
    cycle: int  # the GEO cycle it was raised in
    text: str
    file: str = ""
    line: int = 0  # from 1; 0 = no place in a program
    column: int = 0  # from 1
    state: AlarmState = AlarmState.ACTIVE

    @property
    def warning(self) -> bool:
        """A warning: acknowledging it clears it."""
        return self.severity <= Severity.WARNING

    def __str__(self) -> str:
        where = f"{self.file}:{self.line}:{self.column}" if self.file else ""
        return describe_alarm(self.sequence, self.state.name.lower(),
                              self.severity.name.lower(), self.id, self.channel, where, self.text)


@dataclass(frozen=True, slots=True)
class AlarmView:
    """The alarms as readers see them: the change counter, the active list and the
    history, newest first. Replaced whole on every change."""

    changes: int = 0  # counts every raise, acknowledge and clear
    active: tuple[Alarm, ...] = ()
    history: tuple[Alarm, ...] = ()
    raised: int = 0  # alarms raised since the service started (the last sequence number)


class AlarmLog:
    """The alarms of the whole kernel. Changed on the cycle thread only (raise, the
    acknowledge commands, RESET); ``view`` is read from any thread."""

    def __init__(self, history_max: int = ALARM_HISTORY_MAX,
                 active_max: int = ALARM_ACTIVE_MAX) -> None:
        self.history_max = history_max
        self.active_max = active_max
        self.view = AlarmView()
        self._alarms: dict[int, Alarm] = {}  # active or in the history, by sequence
        self._active: list[int] = []  # sequence numbers, oldest first
        self._history: deque[int] = deque(maxlen=history_max)  # oldest first
        self._sequence = 0
        self._changes = 0
        self._cycle = 0
        self._kernel_ns = 0

    def tick(self, cycle: int, kernel_ns: int) -> None:
        """The cycle now running: the time stamp of what it raises."""
        self._cycle, self._kernel_ns = cycle, kernel_ns

    def raise_error(self, error: ErrorLike, channel: int,
                    alarm_class: AlarmClass | None = None) -> Alarm:
        """Raise ``error`` of ``channel`` as an alarm (its class from its id unless
        given) and return it; the active alarm of the same fault when there is one as
        grave (see the module docstring)."""
        cls = class_of(error.id) if alarm_class is None else alarm_class
        severity = Severity.WARNING if error.warning else (
            Severity.FATAL if cls == AlarmClass.KERNEL or error.id in RESTART_IDS
            else Severity.ERROR)
        same = self._active_fault(error, channel)
        if same is not None:
            if severity <= same.severity:
                return same
            self._set_state(same.sequence, AlarmState.CLEARED)  # the graver one replaces it
        self._sequence += 1
        alarm = Alarm(self._sequence, error.id, severity, cls, channel, time.time_ns(),
                      self._kernel_ns, self._cycle, error.text, error.file, error.line,
                      error.column)
        self._alarms[alarm.sequence] = alarm
        self._active.append(alarm.sequence)
        if len(self._history) == self.history_max and self._history:
            dropped = self._history[0]
            if dropped not in self._active:
                self._alarms.pop(dropped, None)
        self._history.append(alarm.sequence)
        if len(self._active) > self.active_max:  # the oldest makes room (logged)
            oldest = self._active[0]
            log.warning("alarm list full (limits.alarm_active_max %d): %s cleared",
                        self.active_max, self._alarms[oldest])
            self._set_state(oldest, AlarmState.CLEARED)
        self._publish()
        return alarm

    def _active_fault(self, error: ErrorLike, channel: int) -> Alarm | None:
        """The active alarm of the fault ``error`` of ``channel``: the same id and place."""
        for sequence in self._active:
            alarm = self._alarms[sequence]
            if (alarm.id, alarm.channel, alarm.file, alarm.line, alarm.column) == (
                    error.id, channel, error.file, error.line, error.column):
                return alarm
        return None

    def acknowledge(self, sequence: int) -> Refusal | None:
        """Acknowledge the alarm numbered ``sequence``: an error stays active until
        RESET, a warning is cleared. A cleared or acknowledged alarm stays as it is."""
        alarm = self._alarms.get(sequence)
        if alarm is None:
            listed = ", ".join(str(s) for s in self._active) or "none"
            return Refusal(RefusalReason.NOT_FOUND,
                           f"no alarm has the sequence number {sequence} (active alarms: "
                           f"{listed}; `cnc alarms` lists them)")
        if alarm.state == AlarmState.ACTIVE:
            self._set_state(sequence, AlarmState.CLEARED if alarm.warning
                            else AlarmState.ACKNOWLEDGED)
            self._publish()
        return None

    def acknowledge_all(self) -> None:
        """Acknowledge every active alarm."""
        waiting = [s for s in self._active if self._alarms[s].state == AlarmState.ACTIVE]
        for sequence in waiting:
            alarm = self._alarms[sequence]
            self._set_state(sequence, AlarmState.CLEARED if alarm.warning
                            else AlarmState.ACKNOWLEDGED)
        if waiting:
            self._publish()

    def reset_channel(self, channel: int) -> None:
        """RESET of ``channel``: its alarms are cleared, except those only a restart
        clears (KERNEL class, axis configuration); they stay in the history."""
        cleared = [s for s in self._active
                   if self._alarms[s].channel == channel
                   and self._alarms[s].severity < Severity.FATAL]
        for sequence in cleared:
            self._set_state(sequence, AlarmState.CLEARED)
        if cleared:
            self._publish()

    def restart(self) -> None:
        """The kernel's RESET (a restart): every active alarm is cleared."""
        active = list(self._active)
        for sequence in active:
            self._set_state(sequence, AlarmState.CLEARED)
        if active:
            self._publish()

    def _set_state(self, sequence: int, state: AlarmState) -> None:
        self._alarms[sequence] = replace(self._alarms[sequence], state=state)
        self._changes += 1
        if state == AlarmState.CLEARED:
            self._active.remove(sequence)
            if sequence not in self._history:
                self._alarms.pop(sequence)

    def _publish(self) -> None:
        self._changes += 1
        alarms = self._alarms
        self.view = AlarmView(
            self._changes,
            tuple(alarms[s] for s in reversed(self._active)),
            tuple(alarms[s] for s in reversed(self._history)),
            self._sequence,
        )
