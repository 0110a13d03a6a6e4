"""What the alarms page lists, and its acknowledge: the service's alarm objects.

The service raises every error and warning of kernel, decoder, syntax check and service
as an alarm (docs/alarms.md; OPC 40502's CncAlarmType): ``AsyncClient.alarms`` reads the
active list, ``acknowledge_alarm`` acknowledges one by its sequence number (an error
stays active until RESET, a warning is cleared). This module is the one place the web
HMI knows that.
"""

from __future__ import annotations

from dataclasses import dataclass

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


def _severity(value: int) -> str:
    try:
        return Severity(value).name.lower()
    except ValueError:
        return str(value)


async def read_alarms(client: AsyncClient) -> list[Alarm]:
    """The active alarms, oldest first (the newest is the last)."""
    listed = await client.alarms()
    return [Alarm(a.sequence, a.channel, a.id, _severity(int(a.severity)),
                  AlarmState(a.state).name.lower(), a.file, a.line, a.column, a.text)
            for a in reversed(listed.active)]


async def acknowledge(client: AsyncClient, sequence: int) -> None:
    """Acknowledge the alarm numbered ``sequence`` (ADS 0x70C for an unknown number)."""
    await client.acknowledge_alarm(sequence)
