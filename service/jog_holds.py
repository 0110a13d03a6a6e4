"""The dead-man of jogging: a jog key is held only while the connection that pressed it
lives and renews it (issue 36, point 2).

A continuous jog moves while ``manual_jog_plus_w`` / ``manual_jog_minus_w`` is TRUE. A
client that pressed the key and then died (killed, crashed, its network gone) would
leave the axis running until another client released it. So the service remembers,
per jog key, which connection pressed it last and when (``JogHolds``):

- the connection ends (ADS: its TCP connection closed; ZeroMQ: its socket's
  ``DISCONNECTED``, or libzmq's heartbeat ending it): its keys are released at once;
- a key not renewed within ``[limits] jog_hold_timeout_s`` is released, whatever the
  wire: a client renews by writing TRUE again (the kernel takes TRUE on a pressed key
  as no new press; our clients renew every ``clients.jog_hold.RENEW_S``); a connection
  that hangs or a network that drops packets silently ends the jog so.

A release is the write a client would make (FALSE to the key), queued for the kernel
like any write: the kernel knows nothing of connections. Writing FALSE, or TRUE from
another connection (which then holds it), ends the hold of the one before. Holds are
keyed by the object entry, so every alias of a key (name, handle, address, HLI symbol)
is one key.
"""

from __future__ import annotations

import asyncio
import logging
from collections.abc import Callable, Hashable
from dataclasses import dataclass
from time import perf_counter
from typing import Any

from cnc_objects.objects import Entry

from .kernel.commands import Refusal

log = logging.getLogger(__name__)

#: The objects whose TRUE is held by its connection (the continuous-jog keys).
HELD_ELEMENTS = frozenset({"manual_jog_plus_w", "manual_jog_minus_w"})
#: A key not renewed for this long is released by default ([limits] jog_hold_timeout_s).
JOG_HOLD_TIMEOUT_S = 1.0

Submit = Callable[[Any, Callable[[Refusal | None], None]], None]


@dataclass(slots=True)
class _Hold:
    entry: Entry  # the key
    holder: Hashable  # the connection that pressed the key (its front end's identity)
    renewed_s: float  # perf_counter() of the last TRUE written


class JogHolds:
    """Which connection holds which jog key; releases them when it ends or stops
    renewing. Runs on the event loop."""

    def __init__(self, loop: asyncio.AbstractEventLoop, submit: Submit,
                 timeout_s: float) -> None:
        """``submit(command, done)`` queues a kernel command (``Kernel.submit``);
        ``timeout_s``: release a key not renewed for this long (0: never)."""
        self._loop = loop
        self._submit = submit
        self.timeout_s = timeout_s
        self._holds: dict[int, _Hold] = {}  # by the key's handle
        self._timer: asyncio.TimerHandle | None = None
        self.released = 0  # keys released by the dead-man, since start

    @staticmethod
    def is_held(entry: Entry) -> bool:
        """Is ``entry`` a key whose TRUE is held by its connection?"""
        return entry.obj.element in HELD_ELEMENTS

    def written(self, holder: Hashable, entry: Entry, value: Any) -> None:
        """``holder`` wrote ``value`` to the jog key ``entry`` (queued for the kernel)."""
        if not value:
            self._holds.pop(entry.handle, None)
            return
        self._holds[entry.handle] = _Hold(entry, holder, perf_counter())
        if self.timeout_s > 0 and self._timer is None:
            self._timer = self._loop.call_later(self.timeout_s, self._expire)

    def ended(self, holder: Hashable, how: str) -> None:
        """The connection ``holder`` is gone (``how``: a few words for the log): release
        every key it holds."""
        for hold in [h for h in self._holds.values() if h.holder == holder]:
            self._release(hold, f"its connection {how}")

    def _expire(self) -> None:
        """Release the keys not renewed in time; come back for the next deadline."""
        self._timer = None
        now_s = perf_counter()
        for hold in list(self._holds.values()):
            if now_s - hold.renewed_s >= self.timeout_s:
                self._release(hold, f"not renewed for {self.timeout_s:g} s "
                              "([limits] jog_hold_timeout_s)")
        if self._holds:
            first_s = min(h.renewed_s for h in self._holds.values())
            self._timer = self._loop.call_later(
                max(first_s + self.timeout_s - now_s, 0.001), self._expire)

    def _release(self, hold: _Hold, why: str) -> None:
        entry = hold.entry
        del self._holds[entry.handle]
        assert entry.write is not None  # only writable keys are held
        self.released += 1
        log.warning("jog key %s released: %s", entry.obj.name, why)
        self._submit(entry.write(False), _ignore)

    def close(self) -> None:
        """Stop the timer (the service stops)."""
        if self._timer is not None:
            self._timer.cancel()
            self._timer = None


def _ignore(refusal: Refusal | None) -> None:
    """A release is always accepted (``ManualMode.jog``)."""
