"""Helpers for tests against a ``cnc-service``: run a program to its end, wait until an
object has a value.

    status = run_program(cnc_client, "part.nc", timeout_s=60)
    wait_for(cnc_client, "ch1.mc_active_state_r", 3)                  # a value (==)
    wait_for(cnc_client, "ch1.actual_path_velocity", lambda v: v > 0)  # a predicate

Each is written once, as a coroutine over an ``AsyncClient`` (``run_program_async``,
``wait_for_async``); the blocking forms take a ``Client``. Waiting for a value uses a
subscription (the service sends each change), never a polling sleep.
"""

from __future__ import annotations

import asyncio
import contextlib
import os
from collections import deque
from collections.abc import Callable
from pathlib import Path
from typing import Any

from cnc_objects.clients import AdsError, AsyncClient, ChannelStatus, Client
from cnc_objects.clients.errors import AdsTimeoutError
from cnc_objects.clients.sync_transport import drive

PROGRAM_TIMEOUT_S = 60.0  # wall time for a program to end (virtual clock: usually far less)
WAIT_TIMEOUT_S = 10.0  # wall time for an object to reach a value
_SEEN = 10  # how many of the last values a failed wait reports

Program = str | os.PathLike[str]
Expected = Any | Callable[[Any], bool]


async def run_program_async(
    client: AsyncClient, program: Program, channel: int = 1,
    timeout_s: float = PROGRAM_TIMEOUT_S,
) -> ChannelStatus:
    """Run ``program`` in ``channel`` to its end; return the channel's status then.

    ``program``: the name of a stored program, or a local file (a ``Path``) that is
    uploaded first under its file name. Raises ``ChannelError`` (with the channel's
    error lines) when the channel went to ERROR, ``AdsError`` when the start is refused,
    ``AdsTimeoutError`` when the program has not ended after ``timeout_s`` of wall time;
    the program is then stopped (RESET), so that it cannot disturb the next test.
    """
    if isinstance(program, os.PathLike):
        path = Path(program)
        await client.upload(path.name, path.read_bytes())
        name = path.name
    else:
        name = program
    await client.run_program(name, channel)
    try:
        await client.wait_program(channel, timeout_s)
    except AdsTimeoutError:
        with contextlib.suppress(AdsError):  # the service may be what does not answer
            await client.reset(channel)
        raise
    return await client.status(channel)


def run_program(
    client: Client, program: Program, channel: int = 1, timeout_s: float = PROGRAM_TIMEOUT_S,
) -> ChannelStatus:
    """``run_program_async`` for the blocking ``Client``."""
    return drive(run_program_async(_core(client, "run_program"), program, channel, timeout_s))


async def wait_for_async(
    client: AsyncClient, name: str, expected: Expected, timeout_s: float = WAIT_TIMEOUT_S,
) -> Any:
    """Wait until the object ``name`` has a value that equals ``expected`` or, when
    ``expected`` is callable, for which ``expected(value)`` is true; return that value.

    Subscribes to the object's changes (the first sample is its current value), so a
    value held for a single kernel cycle is seen too. ``pytest.approx(x)`` works as
    ``expected`` for floats. Raises ``AdsTimeoutError`` naming the last values seen when
    none matched within ``timeout_s`` of wall time.
    """
    matches, wanted = _matcher(expected)
    seen: deque[Any] = deque(maxlen=_SEEN)
    samples = client.subscribe(name, cycle_ms=0)  # every cycle: see a one-cycle value
    deadline = asyncio.timeout(timeout_s)
    try:
        async with contextlib.aclosing(samples), deadline:
            async for sample in samples:
                if matches(sample.value):
                    return sample.value
                seen.append(sample.value)
    except TimeoutError:
        if not deadline.expired():
            raise  # a request timed out (AdsTimeoutError), not the wait
        values = ", ".join(map(repr, seen)) if seen else "none arrived"
        raise AdsTimeoutError(
            f"{name} did not {wanted} within {timeout_s:g} s; last values: {values}"
        ) from None
    raise AssertionError("a subscription ended")  # pragma: no cover - it never ends


def wait_for(client: Client, name: str, expected: Expected,
             timeout_s: float = WAIT_TIMEOUT_S) -> Any:
    """``wait_for_async`` for the blocking ``Client``.

    The blocking client cannot stop waiting for a sample that does not come, so the
    wait subscribes over a second connection to the same endpoint, on an event loop of
    its own; call it where no event loop runs (in async code, use ``wait_for_async``).
    """
    _core(client, "wait_for")
    try:
        asyncio.get_running_loop()
    except RuntimeError:
        pass
    else:
        raise RuntimeError("wait_for blocks; in async code, await wait_for_async(...)")
    timeout = client._core._t.timeout_s  # the same request timeout as the test's client
    curve = client._core._t.curve  # and the same CURVE keys, for a service with --keys
    key_file = None if curve is None else curve.key_file
    server_key = None if curve is None else curve.server_key_file

    async def wait() -> Any:
        async with AsyncClient(client.endpoint, timeout_s=timeout, key_file=key_file,
                               server_key=server_key) as own:
            return await wait_for_async(own, name, expected, timeout_s)

    return asyncio.run(wait())


def _core(client: Client, helper: str) -> AsyncClient:
    """The coroutine side of a blocking client (its methods run on it through ``drive``)."""
    if isinstance(client, AsyncClient):
        raise TypeError(f"{helper} takes a blocking Client; with an AsyncClient, "
                        f"await {helper}_async(...)")
    return client._core


def _matcher(expected: Expected) -> tuple[Callable[[Any], bool], str]:
    """The test a value must pass and how the timeout error names it."""
    if callable(expected):
        return expected, f"satisfy {getattr(expected, '__name__', repr(expected))}"
    return (lambda value: value == expected), f"become {expected!r}"
