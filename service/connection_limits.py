"""What the open connections of one front end may hold: how many, and (ADS) how many
bytes of frames that have not completed yet.

Each front end (ZeroMQ, ADS) has one ``ConnectionLimits`` with the ``[limits]`` keys
``connections_per_front_end``, ``frame_timeout_s`` and ``receive_buffer_bytes_total``.
A connection asks to be ``admit``-ted when it opens and is ``release``-d when it
closes; the ADS front end reports its parser's buffered bytes after every read
(``buffer``), and closes the connection when the total would go over the budget. Every
refusal is logged through a ``ThrottledWarning``: a flood of connections must not
flood the log as well.
"""

from __future__ import annotations

import logging

from .limits import LimitsConfig
from .log_throttle import ThrottledWarning

log = logging.getLogger(__name__)


class ConnectionLimits:
    """Open connections and bytes of incomplete frames of one front end (``name``)."""

    def __init__(self, name: str, limits: LimitsConfig) -> None:
        self.name = name
        self.max_connections = limits.connections_per_front_end
        self.frame_timeout_s = limits.frame_timeout_s
        self.budget_bytes = limits.receive_buffer_bytes_total
        self.open = 0  # connections admitted and not yet released
        self.buffered_bytes = 0  # bytes of incomplete frames of all its connections
        self.over_cap = ThrottledWarning(
            log, f"{name}: connection closed: {self.max_connections} are open, the most "
            "one front end serves ([limits] connections_per_front_end)")
        self.over_budget = ThrottledWarning(
            log, f"{name}: connection closed: its incomplete frame would take the receive "
            f"buffers of all connections over {self.budget_bytes} bytes "
            "([limits] receive_buffer_bytes_total)")
        self.timed_out = ThrottledWarning(
            log, f"{name}: connection closed: a frame incomplete after "
            f"{self.frame_timeout_s:g} s ([limits] frame_timeout_s)")

    def admit(self, peer: str) -> bool:
        """Count one more connection from ``peer``; False (logged) when the cap is
        reached: the caller closes it."""
        if self.open >= self.max_connections:
            self.over_cap.note(peer)
            return False
        self.open += 1
        return True

    def release(self, buffered_bytes: int) -> None:
        """A connection admitted before is gone, with the bytes it still accounted."""
        self.open -= 1
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
