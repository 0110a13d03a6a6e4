"""What the alarms page lists, and its acknowledge: the service's alarm objects.

The service raises every error and warning of kernel, decoder, syntax check and service
as an alarm (docs/alarms.md; OPC 40502's CncAlarmType): ``AsyncClient.alarms`` reads the
active list, ``acknowledge_alarm`` acknowledges one by its sequence number (an error
stays active until RESET, a warning is cleared), ``acknowledge_all_alarms`` all; with
``history=True`` it also reads the last alarms raised (newest first). This module is the
one place the web HMI knows that.
"""

from __future__ import annotations

from dataclasses import dataclass

from cnc_objects.clients.alarm_ops import AlarmInfo
from cnc_objects.clients.client import AsyncClient
from cnc_objects.protocol.alarm_values import AlarmState, Severity


@dataclass(frozen=True, slots=True)
class Alarm:
    """One alarm as the page shows it."""

    sequence: int  # names the alarm for ``acknowledge``
    channel: int  # 0 = the platform (the service)
    id: int
    severity: str  # "info", "warning", "error" or "fatal"
    state: str  # "active", "acknowledged"
    file: str
    line: int
    column: int
    text: str
    time: str  # when it was raised, ISO 8601 UTC (``2026-11-28T10:49:21.5Z``)


def _severity(value: int) -> str:
    try:
        return Severity(value).name.lower()
    except ValueError:
        return str(value)


def _alarm(a: AlarmInfo) -> Alarm:
    return Alarm(a.sequence, a.channel, a.id, _severity(int(a.severity)),
                 AlarmState(a.state).name.lower(), a.file, a.line, a.column, a.text,
                 a.time.isoformat().replace("+00:00", "Z"))


async def read_alarms(client: AsyncClient) -> list[Alarm]:
    """The active alarms, oldest first (the newest is the last)."""
    listed = await client.alarms()
    return [_alarm(a) for a in reversed(listed.active)]


async def read_history(client: AsyncClient) -> list[Alarm]:
    """The last alarms raised (``alarm_history_max`` of them), newest first, each with
    its state now (active, acknowledged or cleared)."""
    listed = await client.alarms(history=True)
    return [_alarm(a) for a in listed.history]


async def acknowledge_all(client: AsyncClient) -> None:
    """Acknowledge every active alarm (errors stay active until RESET)."""
    await client.acknowledge_all_alarms()


async def acknowledge(client: AsyncClient, sequence: int) -> None:
    """Acknowledge the alarm numbered ``sequence`` (ADS 0x70C for an unknown number)."""
    await client.acknowledge_alarm(sequence)
