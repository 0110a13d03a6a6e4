"""The alarms over MQTT (docs/mqtt.md, docs/alarms.md):

    cnc/<machine>/alarms/active   the active alarms, JSON (retained, QoS 1), after each change
    cnc/<machine>/alarms/event    one message per event: raised, acknowledged, cleared (QoS 1)

The service side (``follow``, in the source's session) subscribes to ``alarm_changes_r``
and at each change reads the lists; the broker side (``publish``) sends the events in
order, then the list. Events that come while the broker is away wait (the newest
``EVENTS_KEPT``); after a reconnect the list goes out again. Events during a service
outage are not seen: the list after the reconnect says what is active.
"""

from __future__ import annotations

import asyncio
import json
import logging
from collections import deque

import aiomqtt

from .. import names
from ..alarm_ops import AlarmEvent, AlarmList, events_since, seen_states
from ..client import AsyncClient
from .topics import Topics

log = logging.getLogger(__name__)

QOS = 1
EVENTS_KEPT = 1000  # events waiting for the broker; older ones are dropped (logged)
CHANGES_OBJECT = names.alarm_changes_r


def list_payload(listed: AlarmList) -> bytes:
    """The retained list: the change counter, the count and the active alarms."""
    return json.dumps({"changes": listed.changes, "active_count": listed.active_count,
                       "active": [a.as_dict() for a in listed.active]}).encode()


def event_payload(event: AlarmEvent) -> bytes:
    """One event: its kind and the alarm (as ``cnc --json alarms`` prints it)."""
    return json.dumps({"event": event.kind, **event.alarm.as_dict()}).encode()


class AlarmFeed:
    """Alarm messages between the service side and the broker side of the bridge."""

    def __init__(self, topics: Topics) -> None:
        self.topics = topics
        self.published = 0  # alarm messages handed to the broker
        self._list: bytes | None = None  # the newest list, not yet published when _dirty
        self._dirty = False
        self._events: deque[bytes] = deque()
        self._ready = asyncio.Event()

    async def follow(self, client: AsyncClient) -> None:
        """Service side: read the lists at each change of the alarms; returns when the
        subscription ends."""
        seen = None
        async for _sample in client.subscribe(CHANGES_OBJECT):
            listed = await client.alarms(history=True)
            if seen is None:
                seen = seen_states(listed)
            else:
                for event in events_since(seen, listed):
                    if len(self._events) == EVENTS_KEPT:
                        log.warning("alarm events: the broker is behind; dropped %r",
                                    self._events.popleft()[:80])
                    self._events.append(event_payload(event))
            self._list, self._dirty = list_payload(listed), True
            self._ready.set()

    async def publish(self, mqtt: aiomqtt.Client) -> None:
        """Broker side: events in order, then the list (retained); at once after a
        (re)connect when a list is known."""
        if self._list is not None:
            self._dirty = True
            self._ready.set()
        while True:
            await self._ready.wait()
            self._ready.clear()
            while self._events:
                await mqtt.publish(self.topics.alarm_event, self._events[0], qos=QOS)
                self._events.popleft()  # only once the broker took it
                self.published += 1
            if self._dirty and self._list is not None:
                self._dirty = False
                await mqtt.publish(self.topics.alarm_list, self._list, qos=QOS, retain=True)
                self.published += 1
