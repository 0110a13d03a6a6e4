"""What the bridge's two reconnect loops share: backoff, and sessions a stop always ends."""

from __future__ import annotations

import asyncio
from collections.abc import Awaitable, Callable, Coroutine
from typing import Any, TypeVar

T = TypeVar("T")


class Backoff:
    """Delays ``initial_s``, doubling up to ``max_s``; ``reset()`` after a success.

    The first attempt after a loss waits ``initial_s``, so a broker or service that comes
    straight back is reached almost at once, and one that stays away costs a connection
    attempt every ``max_s`` at most.
    """

    def __init__(self, initial_s: float, max_s: float) -> None:
        if not 0 < initial_s <= max_s:
            raise ValueError(f"backoff needs 0 < initial ({initial_s}) <= max ({max_s})")
        self.initial_s = initial_s
        self.max_s = max_s
        self._next_s = initial_s

    def reset(self) -> None:
        """The connection worked: the next loss starts again at ``initial_s``."""
        self._next_s = self.initial_s

    def next_delay_s(self) -> float:
        """The delay before the next attempt (and double the one after)."""
        delay = self._next_s
        self._next_s = min(self._next_s * 2, self.max_s)
        return delay

    async def wait(self) -> None:
        """Wait the next delay."""
        await asyncio.sleep(self.next_delay_s())


async def session(
    coro: Coroutine[Any, Any, T],
    name: str,
    before_cancel: Callable[[], Awaitable[None]] | None = None,
) -> T:
    """Await ``coro`` in a task of its own; when the caller is cancelled, run
    ``before_cancel``, cancel the task, wait for it and raise ``CancelledError``.

    Why not await ``coro`` directly: in Python 3.11 a TaskGroup whose children fail with
    errors of their own while it is being cancelled raises those errors instead of the
    cancellation, and a reconnect loop that handles them would run on after a stop. Here
    the caller's cancellation is seen on the shield and always re-raised.
    """
    task = asyncio.create_task(coro, name=name)
    try:
        return await asyncio.shield(task)
    except asyncio.CancelledError:
        if before_cancel is not None:
            await before_cancel()
        task.cancel()
        await asyncio.gather(task, return_exceptions=True)
        raise
