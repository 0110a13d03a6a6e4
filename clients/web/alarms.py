"""What the alarms page lists, and its acknowledge: today the channels' error lists.

Each channel keeps its errors in ``ch<c>.mc_error_<k>_{id,file,line,column,text,warning}_r``
(``mc_error_count_r`` of them); RESET clears them. This module is the one place that
knows it: when the service has alarm objects (OPC 40502's CncAlarmType, see
docs/isg-notes.md), ``read_alarms`` and ``acknowledge`` read and acknowledge those
instead, and the page and API stay as they are.
"""

from __future__ import annotations

from dataclasses import dataclass

from cnc_objects.clients.client import AsyncClient

ERROR_SLOTS = 8  # the service keeps the first eight errors of a channel in objects
_FIELDS = ("id", "file", "line", "column", "text", "warning")


@dataclass(frozen=True, slots=True)
class Alarm:
    """One alarm as the page shows it."""

    channel: int
    id: int
    severity: str  # "error" or "warning"
    file: str
    line: int
    column: int
    text: str


async def read_alarms(client: AsyncClient, channels: list[int]) -> list[Alarm]:
    """The alarms of ``channels``, in each channel's order (one sum read per channel)."""
    found: list[Alarm] = []
    for channel in channels:
        count = int(await client.read(f"ch{channel}.mc_error_count_r"))
        slots = range(1, min(count, ERROR_SLOTS) + 1)
        names = [f"ch{channel}.mc_error_{k}_{f}_r" for k in slots for f in _FIELDS]
        values = await client.read_many(names) if names else {}
        for k in slots:
            v = [values[f"ch{channel}.mc_error_{k}_{f}_r"] for f in _FIELDS]
            found.append(Alarm(channel, int(v[0]), "warning" if v[5] else "error",
                               str(v[1]), int(v[2]), int(v[3]), str(v[4])))
    return found


async def acknowledge(client: AsyncClient, channel: int) -> None:
    """Acknowledge the channel's alarms: RESET, which clears its error list."""
    await client.reset(channel)
