"""What one OPC UA client may cost the service: the ``[limits]`` keys of the OPC UA front
end applied to an asyncua server (docs/limits.md, docs/opcua.md "Limits").

asyncua keeps some limits of its own; they are set from ``[limits]``:

- TCP connections (``connections_per_front_end``, asyncua's ``max_connections``: one more
  is closed at once);
- a connection that has not activated a session after ``opcua_activation_timeout_s``
  is closed (asyncua's ``max_pending_activation_seconds``): a half-open secure channel;
- the longest message a client may send (``max_frame_bytes``: asyncua's transport
  limits; longer: Bad_RequestTooLarge and the connection is closed);
- subscriptions of all sessions (``opcua_subscriptions_total``, asyncua's
  ``max_subscriptions``: Bad_TooManySubscriptions);
- the queue of a monitored item (``opcua_queue_size_max``: asyncua revises a larger
  requested QueueSize down to it, RevisedQueueSize says so).

What asyncua lacks is a thin guard here, in front of its own services (``SessionGuard``):

- sessions (``opcua_sessions``): CreateSession beyond answers Bad_TooManySessions;
- subscriptions of one session (``opcua_subscriptions_per_session``):
  Bad_TooManySubscriptions;
- monitored items of one session and of all (``opcua_monitored_items_per_session``,
  ``opcua_monitored_items_total``): each item of a CreateMonitoredItems beyond either is
  answered Bad_TooManyMonitoredItems, the items before it are created;
- notifications in one PublishResponse (``opcua_notifications_per_publish``, and the
  subscription's own MaxNotificationsPerPublish when smaller): the rest wait for the next
  publish, MoreNotifications says so.

Nothing else changes over a limit: the session, its other subscriptions and items, the
other sessions and front ends are served on.
"""

from __future__ import annotations

import logging
import math
import weakref
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from asyncua import Server, ua
from asyncua.common.utils import ServiceError
from asyncua.server.internal_server import InternalServer
from asyncua.server.internal_session import InternalSession, SessionState
from asyncua.server.internal_subscription import InternalSubscription

from . import chunk_guard

log = logging.getLogger(__name__)

_S = ua.StatusCodes


@dataclass(frozen=True, slots=True)
class OpcUaLimits:
    """The ``[limits]`` keys the OPC UA front end keeps (``from_config``)."""

    connections: int = 64
    activation_timeout_s: float = 10.0
    max_message_bytes: int = 1 << 20
    sessions: int = 32
    subscriptions_per_session: int = 20
    subscriptions_total: int = 200
    monitored_items_per_session: int = 2000
    monitored_items_total: int = 10_000
    queue_size_max: int = 100
    notifications_per_publish: int = 10_000

    @classmethod
    def from_config(cls, limits: Any) -> OpcUaLimits:
        """The OPC UA part of a ``LimitsConfig``."""
        return cls(
            connections=limits.connections_per_front_end,
            activation_timeout_s=limits.opcua_activation_timeout_s,
            max_message_bytes=limits.max_frame_bytes,
            sessions=limits.opcua_sessions,
            subscriptions_per_session=limits.opcua_subscriptions_per_session,
            subscriptions_total=limits.opcua_subscriptions_total,
            monitored_items_per_session=limits.opcua_monitored_items_per_session,
            monitored_items_total=limits.opcua_monitored_items_total,
            queue_size_max=limits.opcua_queue_size_max,
            notifications_per_publish=limits.opcua_notifications_per_publish,
        )


def apply_limits(server: Server, limits: OpcUaLimits) -> SessionGuard:
    """Set asyncua's own limits of ``server`` from ``limits`` and put the guard of the
    others in front of its services (before ``server.start()``)."""
    chunk_guard.install()
    iserver = server.iserver
    iserver.max_connections = limits.connections
    iserver.max_pending_activation_seconds = limits.activation_timeout_s
    iserver.max_subscriptions = limits.subscriptions_total
    iserver.max_monitored_item_queue_size = limits.queue_size_max
    # asyncua's own count of activated sessions (class-wide: one server per service)
    # answers ActivateSession Bad_MaxConnectionsReached beyond it; ours refuses first
    InternalSession.max_connections = limits.sessions
    chunk = server.limits.max_recv_buffer
    server.limits.max_message_size = limits.max_message_bytes
    server.limits.max_chunk_count = math.ceil(limits.max_message_bytes / chunk)
    return SessionGuard(iserver, limits)


class SessionGuard:
    """The limits asyncua lacks, kept in front of one server's session and subscription
    services: each wraps the service's method on the instance (asyncua calls it there)."""

    def __init__(self, iserver: InternalServer, limits: OpcUaLimits) -> None:
        self.limits = limits
        self._iserver = iserver
        self._sessions: weakref.WeakSet[InternalSession] = weakref.WeakSet()
        service = iserver.subscription_service
        self._subscriptions = service.subscriptions
        create_session = iserver.create_session
        create_subscription = service.create_subscription
        create_items = service.create_monitored_items

        def guarded_create_session(name: str, *args: Any, **kwargs: Any) -> InternalSession:
            # asyncua's signature: (name, user=..., external=False); clients' are external
            external = bool(kwargs.get("external", args[1] if len(args) > 1 else False))
            if external and self.open_sessions() >= limits.sessions:
                log.warning("OPC UA session from %s refused: %d sessions open "
                            "([limits] opcua_sessions)", name, limits.sessions)
                raise ServiceError(_S.BadTooManySessions)
            session = create_session(name, *args, **kwargs)
            if external:
                self._sessions.add(session)
            return session

        async def guarded_create_subscription(
                params: ua.CreateSubscriptionParameters, callback: Callable[..., Any],
                session_id: ua.NodeId, request_callback: Callable[..., Any] | None = None,
        ) -> ua.CreateSubscriptionResult:
            held = sum(1 for sub in self._subscriptions.values() if sub.session_id == session_id)
            if held >= limits.subscriptions_per_session:
                log.warning("OPC UA subscription refused: the session holds %d "
                            "([limits] opcua_subscriptions_per_session)", held)
                raise ServiceError(_S.BadTooManySubscriptions)
            result: ua.CreateSubscriptionResult = await create_subscription(
                params, callback, session_id, request_callback=request_callback)
            sub = self._subscriptions.get(result.SubscriptionId)
            if sub is not None:
                asked = int(params.MaxNotificationsPerPublish)
                most = min(asked, limits.notifications_per_publish) if asked > 0 \
                    else limits.notifications_per_publish
                _bound_publish(sub, most)
            return result

        async def guarded_create_items(params: ua.CreateMonitoredItemsParameters
                                       ) -> list[ua.MonitoredItemCreateResult]:
            sub = self._subscriptions.get(params.SubscriptionId)
            if sub is None:
                answer: list[ua.MonitoredItemCreateResult] = await create_items(params)
                return answer  # asyncua's answer to an unknown subscription id
            room = min(limits.monitored_items_per_session - self.items_of(sub.session_id),
                       limits.monitored_items_total - self.items_of(None))
            asked = list(params.ItemsToCreate)
            if len(asked) <= room:
                answer = await create_items(params)
                return answer
            room = max(room, 0)
            log.warning("OPC UA monitored items refused: %d of %d over [limits] "
                        "opcua_monitored_items_per_session (%d) or _total (%d)",
                        len(asked) - room, len(asked), limits.monitored_items_per_session,
                        limits.monitored_items_total)
            params.ItemsToCreate = asked[:room]
            try:
                results: list[ua.MonitoredItemCreateResult] = (
                    await create_items(params) if room else [])
            finally:  # the request as the client sent it, for asyncua's item callbacks
                params.ItemsToCreate = asked
            for _ in asked[room:]:
                refused = ua.MonitoredItemCreateResult()
                refused.StatusCode = ua.StatusCode(_S.BadTooManyMonitoredItems)
                results.append(refused)
            return results

        iserver.create_session = guarded_create_session
        service.create_subscription = guarded_create_subscription
        service.create_monitored_items = guarded_create_items

    def open_sessions(self) -> int:
        """Sessions of clients that are not closed (created or activated)."""
        return sum(1 for s in self._sessions if s.state is not SessionState.Closed)

    def items_of(self, session_id: ua.NodeId | None) -> int:
        """Monitored items of the session ``session_id`` (None: of all sessions)."""
        return sum(len(sub.monitored_item_srv._monitored_items)
                   for sub in self._subscriptions.values()
                   if session_id is None or sub.session_id == session_id)


def _bound_publish(sub: InternalSubscription, most: int) -> None:
    """Make ``sub`` put at most ``most`` data changes in one PublishResponse; the rest
    stay queued (each item's in order) for the next, and MoreNotifications says so."""
    pop = sub._pop_publish_result

    def bounded() -> ua.PublishResult:
        queued = sub._triggered_datachanges
        if sum(len(values) for values in queued.values()) <= most:
            return pop()
        now: dict[int, list[ua.MonitoredItemNotification]] = {}
        rest: dict[int, list[ua.MonitoredItemNotification]] = {}
        room = most
        for handle, values in queued.items():
            taken = values[:room]
            if taken:
                now[handle] = taken
            if len(values) > len(taken):
                rest[handle] = values[len(taken):]
            room -= len(taken)
        sub._triggered_datachanges = now
        result = pop()  # empties the queue: no await in between, nothing else ran
        sub._triggered_datachanges = rest
        result.MoreNotifications = True
        return result

    sub._pop_publish_result = bounded
