"""What the bridge must publish next: the newest sample of each object, and the status.

Samples arrive from the service as fast as the kernel changes objects; the broker takes
them at its own pace. The outbox keeps only the newest sample per object (a value topic
carries the *current* value, retained), so a slow broker costs skipped intermediate
values, never memory or a growing delay. The status is kept the same way.
"""

from __future__ import annotations

import asyncio
from dataclasses import dataclass

from ..client import Sample
from ..object_info import ObjectInfo

ONLINE = "online"
OFFLINE = "offline"


@dataclass(frozen=True, slots=True)
class Pending:
    """One object's newest sample, with what the service says about the object."""

    info: ObjectInfo
    sample: Sample


class Outbox:
    """Newest sample per object, which of them still have to go out, and the status."""

    def __init__(self) -> None:
        self._latest: dict[str, Pending] = {}
        self._dirty: dict[str, None] = {}  # an ordered set: oldest change first
        self._status = OFFLINE
        self._status_sent: str | None = None
        self._wake = asyncio.Event()

    def put(self, info: ObjectInfo, sample: Sample) -> None:
        """A new sample of ``info``; replaces one not published yet."""
        self._latest[info.name] = Pending(info, sample)
        self._dirty[info.name] = None
        self._wake.set()

    def set_status(self, status: str) -> None:
        """Show ``status`` (after the values that are waiting)."""
        if status != self._status:
            self._status = status
            self._wake.set()

    def resend_all(self) -> None:
        """A new broker connection: every value and the status go out again."""
        self._dirty = dict.fromkeys(self._latest)
        self._status_sent = None
        self._wake.set()

    async def wait(self) -> None:
        """Until something is waiting to be published."""
        await self._wake.wait()

    def take(self) -> tuple[list[Pending], str | None]:
        """The samples to publish now (oldest change first) and the status, or None when
        the broker already has it. Both count as sent from here on."""
        self._wake.clear()
        pending = [self._latest[name] for name in self._dirty]
        self._dirty = {}
        status = None if self._status == self._status_sent else self._status
        self._status_sent = self._status
        return pending, status
