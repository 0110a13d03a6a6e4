"""A warning that a client can cause at will, logged now and then with a count.

A client that sends garbage (or does not read its replies) must not flood the log: the
first occurrence is logged with its detail, later ones at most every ``every_s`` seconds,
with how many there were since the last line.
"""

from __future__ import annotations

import logging
from time import perf_counter


class ThrottledWarning:
    """``note(detail)`` for each occurrence; a log line for the first and then at most one
    every ``every_s`` seconds, saying how many were left unlogged in between."""

    def __init__(self, log: logging.Logger, what: str, every_s: float = 10.0) -> None:
        self._log = log
        self._what = what
        self._every_s = every_s
        self._logged_s = -float("inf")
        self._unlogged = 0
        self.count = 0  # occurrences since start

    def note(self, detail: object) -> None:
        """One more occurrence, ``detail`` saying what it was."""
        self.count += 1
        now_s = perf_counter()
        if now_s - self._logged_s < self._every_s:
            self._unlogged += 1
            return
        self._logged_s = now_s
        more = (f" (and {self._unlogged} more in the last {self._every_s:g} s, "
                f"{self.count} since start)") if self._unlogged else ""
        self._unlogged = 0
        self._log.warning("%s: %s%s", self._what, detail, more)
