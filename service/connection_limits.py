"""What the open connections of one front end may hold: how many, who may take a seat
when all are taken, and (ADS) how many bytes of frames that have not completed yet.

Each front end (ZeroMQ, ADS) has one ``ConnectionLimits`` with the ``[limits]`` keys
``connections_per_front_end``, ``idle_connection_s``, ``frame_timeout_s`` and
``receive_buffer_bytes_total``. A connection asks for a ``Seat`` when it opens
(``admit``), marks it ``used`` with each request and gives it back when it closes
(``release``); the ADS front end reports its parser's buffered bytes after every read
(``buffer``), and closes the connection when the total would go over the budget.

A full table makes room (issue 35, hole 11): the newcomer takes the seat of the
*keyless* connection that has been idle longest (it is closed, logged): a keyed
newcomer always, a keyless one when that connection has sent no request for
``idle_connection_s``. Keyless is a peer without a key or route: an ADS peer served by
the loopback rule (or ``--insecure``), a ZeroMQ connection without CURVE or one that
has not completed its handshake. Keyed connections (an ADS route, a CURVE key) are never
closed for a newcomer. So keyless connections can never lock a keyed client out, and
idle ones cannot lock anyone out for longer than ``idle_connection_s``; a newcomer
finds no seat only when every seat is keyed or busy, and the refusal says the table is
full. Every refusal and eviction is logged through a
``ThrottledWarning``: a flood of connections must not flood the log as well.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass, field
from time import perf_counter

from .limits import LimitsConfig
from .log_throttle import ThrottledWarning

log = logging.getLogger(__name__)


@dataclass(eq=False, slots=True)
class Seat:
    """One admitted connection: who, whether keyed, how to close it, when it last asked."""

    peer: str
    keyed: bool  # has a key (CURVE) or a route (ADS): never evicted for a newcomer
    close: Callable[[], None] = field(repr=False)  # ends the connection (evicted)
    used_s: float = field(default_factory=perf_counter)  # last request (accept until one)


class ConnectionLimits:
    """Open connections and bytes of incomplete frames of one front end (``name``)."""

    def __init__(self, name: str, limits: LimitsConfig) -> None:
        self.name = name
        self.max_connections = limits.connections_per_front_end
        self.idle_s = limits.idle_connection_s
        self.frame_timeout_s = limits.frame_timeout_s
        self.budget_bytes = limits.receive_buffer_bytes_total
        self.seats: set[Seat] = set()  # connections admitted and not yet released
        self.buffered_bytes = 0  # bytes of incomplete frames of all its connections
        self.over_cap = ThrottledWarning(
            log, f"{name}: connection refused: the connection table is full, "
            f"{self.max_connections} are open ([limits] connections_per_front_end) and "
            f"none is keyless and idle for {self.idle_s:g} s ([limits] idle_connection_s)")
        self.evicted = ThrottledWarning(
            log, f"{name}: idle keyless connection closed to make room for a newcomer "
            f"(table full: [limits] connections_per_front_end {self.max_connections}, "
            f"idle_connection_s {self.idle_s:g})")
        self.over_budget = ThrottledWarning(
            log, f"{name}: connection closed: its incomplete frame would take the receive "
            f"buffers of all connections over {self.budget_bytes} bytes "
            "([limits] receive_buffer_bytes_total)")
        self.timed_out = ThrottledWarning(
            log, f"{name}: connection closed: a frame incomplete after "
            f"{self.frame_timeout_s:g} s ([limits] frame_timeout_s)")

    @property
    def open(self) -> int:
        """Connections admitted and not yet released."""
        return len(self.seats)

    def admit(self, peer: str, keyed: bool, close: Callable[[], None],
              note: bool = True, force: bool = False) -> Seat | None:
        """A seat for a new connection from ``peer``, making room when the table is full
        (``make_room``); None when there is none: the caller refuses the connection
        (logged unless ``note`` is False). ``force``: a seat even over the cap (a
        connection that is in already)."""
        if not force and len(self.seats) >= self.max_connections \
                and not self.make_room(keyed):
            if note:
                self.over_cap.note(peer)
            return None
        seat = Seat(peer, keyed, close)
        self.seats.add(seat)
        return seat

    def make_room(self, for_keyed: bool) -> bool:
        """Close the keyless connection idle longest, for a keyed newcomer (``for_keyed``)
        always, else when idle for ``idle_s``: True when one was closed (its seat is free
        at once)."""
        idlest = min((s for s in self.seats if not s.keyed), key=_used_s, default=None)
        if idlest is None or (not for_keyed and perf_counter() - idlest.used_s < self.idle_s):
            return False
        self.seats.discard(idlest)
        self.evicted.note(f"{idlest.peer} (idle {perf_counter() - idlest.used_s:.1f} s)")
        idlest.close()
        return True

    def release(self, seat: Seat, buffered_bytes: int) -> None:
        """A connection admitted before is gone, with the bytes it still accounted."""
        self.seats.discard(seat)  # an evicted seat is free already
        self.buffered_bytes -= buffered_bytes

    def buffer(self, peer: str, was_bytes: int, now_bytes: int) -> bool:
        """A connection's incomplete frame went from ``was_bytes`` to ``now_bytes``;
        False (logged) when that takes the total over the budget: the caller closes the
        connection and accounts 0 for it."""
        total = self.buffered_bytes - was_bytes + now_bytes
        if now_bytes > was_bytes and total > self.budget_bytes:
            self.buffered_bytes -= was_bytes
            self.over_budget.note(f"{peer} ({now_bytes} bytes)")
            return False
        self.buffered_bytes = total
        return True


def _used_s(seat: Seat) -> float:
    return seat.used_s
