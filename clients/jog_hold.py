"""Hold a jog key the way the service's dead-man wants it: pressed, renewed, released.

The service releases a pressed jog key (``manual_jog_plus_w`` / ``manual_jog_minus_w``)
when the connection that pressed it ends, and when it is not written TRUE again within
``[limits] jog_hold_timeout_s`` (1 s by default; docs/manual.md, "Dead-man"). A client
that holds a key for longer renews it::

    async with HeldJog(client, "ch1.ax1.manual_jog_plus_w"):
        await asyncio.sleep(2.0)       # X moves; the key is renewed every RENEW_S
    # released here (also when the block raises or is cancelled)

A blocking program renews in its own loop: write TRUE again at least every ``RENEW_S``
(``cnc jog --continuous`` does). A web or panel front end that holds a key while its
user holds a button renews while the button is down and releases when it comes up.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
from types import TracebackType
from typing import Any, Protocol

from .errors import AdsConnectionError, AdsError


class KeyWriter(Protocol):
    """What a held key needs of a client: ``AsyncClient.write`` (a protocol, so that the
    client's own mixins hold keys without an import circle)."""

    async def write(self, name: str, value: Any, units: bool = False) -> None: ...

log = logging.getLogger(__name__)

#: How often a held key is written TRUE again: well inside the service's default
#: jog_hold_timeout_s (1 s), with room for a busy network.
RENEW_S = 0.2


class HeldJog:
    """``async with``: the jog key ``key`` pressed (TRUE) and renewed every ``renew_s``
    until the block ends, then released (FALSE). A press the service refuses raises its
    ``AdsError`` from ``async with``; a renewal it refuses (the channel was held, reset,
    the key released by someone else and pressed in vain) ends the renewals, logged."""

    def __init__(self, client: KeyWriter, key: str, renew_s: float = RENEW_S) -> None:
        self.client = client
        self.key = key
        self.renew_s = renew_s
        self._renewer: asyncio.Task[None] | None = None

    async def __aenter__(self) -> HeldJog:
        await self.client.write(self.key, True)
        self._renewer = asyncio.create_task(self._renew(), name=f"renew {self.key}")
        return self

    async def __aexit__(self, exc_type: type[BaseException] | None,
                        exc: BaseException | None, tb: TracebackType | None) -> None:
        await self.release()

    async def release(self) -> None:
        """Stop renewing and release the key (once; a lost connection released it)."""
        renewer, self._renewer = self._renewer, None
        if renewer is None:
            return
        renewer.cancel()
        with contextlib.suppress(asyncio.CancelledError):
            await renewer
        with contextlib.suppress(AdsConnectionError):  # gone: the service released it
            await self.client.write(self.key, False)

    async def _renew(self) -> None:
        while True:
            await asyncio.sleep(self.renew_s)
            try:
                await self.client.write(self.key, True)
            except AdsError as exc:  # no one awaits this task: log, never raise
                log.warning("jog key %s no longer renewed: %s", self.key, exc)
                return
