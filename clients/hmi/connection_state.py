"""The connection line: connected, or since when the service has not replied.

The session tells every reply (a subscription's sample, the heartbeat read) with
``replied()``; when the session is lost the line reads
``no reply from tcp://… since 10:42:13 (12 s) — values greyed, retrying`` and counts the
seconds on, once a second, until the service answers again. The time is the wall clock
of the HMI's computer (local time), the moment of the last reply; before any reply it is
the moment the HMI started trying.
"""

from __future__ import annotations

import time
from typing import Any

from textual.widgets import Static

REFRESH_S = 1.0  # the age shown counts whole seconds


def no_reply_text(endpoint: str, last_reply_wall_s: float, now_wall_s: float) -> str:
    """``no reply from <endpoint> since 10:42:13 (12 s) — …`` (local wall time)."""
    since = time.strftime("%H:%M:%S", time.localtime(last_reply_wall_s))
    age_s = max(0, int(now_wall_s - last_reply_wall_s))
    return f"no reply from {endpoint} since {since} ({age_s} s) — values greyed, retrying"


class ConnectionLine(Static):
    """One line: ``connected to …`` or the no-reply text, in the warning colour."""

    DEFAULT_CSS = """
    ConnectionLine { height: 1; padding: 0 1; }
    ConnectionLine.lost { background: $warning 40%; color: $text; }
    """

    def __init__(self, endpoint: str, **kwargs: Any) -> None:
        super().__init__("", markup=False, **kwargs)
        self.endpoint = endpoint
        self.last_reply_wall_s = time.time()  # before any reply: since the HMI started
        self.connected = False
        self.text = ""

    def on_mount(self) -> None:
        """Count the seconds without a reply on, once a second."""
        self._show_lost()
        self.set_interval(REFRESH_S, self._tick)

    def replied(self) -> None:
        """The service answered just now."""
        self.last_reply_wall_s = time.time()

    def session_started(self, what: str) -> None:
        """Connected: say to what (``what``: name and version of the service)."""
        self.connected = True
        self.replied()
        self.remove_class("lost")
        self._say(f"connected to {what} at {self.endpoint}")

    def session_lost(self) -> None:
        """The service stopped answering (or never did)."""
        self.connected = False
        self._show_lost()

    def _tick(self) -> None:
        if not self.connected:
            self._show_lost()

    def _show_lost(self) -> None:
        self.add_class("lost")
        self._say(no_reply_text(self.endpoint, self.last_reply_wall_s, time.time()))

    def _say(self, line: str) -> None:
        self.text = line
        self.update(line)
