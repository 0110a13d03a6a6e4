"""``cnc_trace``: record the samples of a program run as rows of kernel time, object, value.

    @pytest.mark.cnc_service(programs=["part.nc"])
    def test_part_trace(cnc_trace):
        cnc_trace.watch(["ch1.ax1.position", "ch1.ax2.position"], cycle_ms=10)
        cnc_trace.watch(["ch1.mc_active_state_r"], on_change=True, cycle_ms=1)
        rows = cnc_trace.run("part.nc")
        assert rows[0] == (0, "ch1.ax1.position", 0.0)

The service runs with repeatable samples (``--samples repeatable``, docs/kernel.md
"Traces that repeat"): every subscription is sampled at its due cycles of kernel time,
none is dropped, and samples carry kernel time. The recorder subscribes while the kernel
rests (its first rows are all at that kernel time), starts the program there, waits for
its end (on the step clock it grants the cycles itself) and returns the rows from the
start to the end of the program time, ordered by kernel time and then by the order the
objects were watched. The same program with the same watches gives the same rows on
every run and on ``--clock virtual``, ``virtual-step`` and ``step``.
"""

from __future__ import annotations

import asyncio
import contextlib
import math
import os
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path
from typing import Any, NamedTuple

from cnc_objects.clients import AsyncClient
from cnc_objects.protocol.values import ChannelState

#: Kernel time 0 of repeatable samples: they carry kernel time as a time since the Unix
#: epoch (``NotificationHub``).
_KERNEL_EPOCH = datetime(1970, 1, 1, tzinfo=UTC)
#: The object whose cyclic samples tell the recorder that every sample up to the end has
#: come (with a round trip after it): subscribed last, so in a pass it is sampled after
#: every watched object.
_MARKER = "cnc_kernel_time_r"
STEP_CHUNK_CYCLES = 1000  # cycles granted per step on the step clock
RUN_TIMEOUT_S = 120.0  # wall time for the run and its samples
REQUEST_TIMEOUT_S = 30.0  # per request; a step of STEP_CHUNK_CYCLES included


class TraceRow(NamedTuple):
    """One sample: the kernel time of its cycle (ns), the object, the value."""

    kernel_ns: int
    name: str
    value: Any


@dataclass(frozen=True)
class Watch:
    """Objects sampled every ``cycle_ms`` of kernel time (0: every cycle), or checked
    then and sent on change."""

    names: tuple[str, ...]
    cycle_ms: int
    on_change: bool


class TraceError(AssertionError):
    """A trace could not be recorded as asked (the kernel was not at rest, the run did
    not end in time)."""


class TraceRecorder:
    """Watches objects over one program run of a service with repeatable samples
    (``cnc_trace`` fixture)."""

    def __init__(self, endpoint: str, stepping: bool) -> None:
        """``endpoint``: the service's ZeroMQ endpoint; ``stepping``: it runs on the step
        clock (the recorder grants the run's cycles)."""
        self.endpoint = endpoint
        self.stepping = stepping
        self.watches: list[Watch] = []

    def watch(self, names: list[str] | tuple[str, ...], cycle_ms: int = 10,
              on_change: bool = False) -> None:
        """Sample ``names`` every ``cycle_ms`` of kernel time (cycles n, 2n, ...), or, with
        ``on_change``, at the first such cycle where the value differs from the last one
        sent. The first row of each is its value when the run starts."""
        if cycle_ms < 0:
            raise ValueError(f"cycle_ms must be 0 (every cycle) or more, not {cycle_ms}")
        self.watches.append(Watch(tuple(names), cycle_ms, on_change))

    def run(self, program: str | os.PathLike[str], channel: int = 1,
            timeout_s: float = RUN_TIMEOUT_S) -> list[TraceRow]:
        """Run ``program`` (a stored name, or a local file uploaded first) in ``channel``
        and return its trace. Blocking: call it where no event loop runs."""
        return asyncio.run(self.run_async(program, channel, timeout_s))

    async def run_async(self, program: str | os.PathLike[str], channel: int = 1,
                        timeout_s: float = RUN_TIMEOUT_S) -> list[TraceRow]:
        """``run`` for async tests."""
        if not self.watches:
            raise ValueError("watch some objects first (cnc_trace.watch([...]))")
        async with AsyncClient(self.endpoint, timeout_s=REQUEST_TIMEOUT_S) as client:
            if isinstance(program, os.PathLike):
                path = Path(program)
                await client.upload(path.name, path.read_bytes())
                program = path.name
            cycle_ns = int(await client.read("cnc_cycle_time_r")) * 1000
            recording = _Recording(cycle_ns)
            async with asyncio.timeout(timeout_s):
                tasks = await self._subscribe(client, recording)
                try:
                    start_ns = recording.start_ns()
                    await client.run_program(str(program), channel)
                    await self._run_to_end(client, channel)
                    program_s = float(await client.read(f"ch{channel}.program_time"))
                    end_ns = start_ns + round(program_s * 1e9 / cycle_ns) * cycle_ns
                    await recording.wait_marker(_last_on_grid(end_ns, self._marker_ns(
                        cycle_ns)), start_ns)
                    # The hub sends a slice's samples in one frame per port: a frame of
                    # another port with samples up to the marker's may follow its frame.
                    # A reply goes out after both, and the subscriptions' tasks take what
                    # came before it before this goes on (their wake-ups are queued first).
                    await client.read(_MARKER)
                finally:
                    for task in tasks:
                        task.cancel()
                    await asyncio.gather(*tasks, return_exceptions=True)
            return recording.rows(end_ns)

    async def _subscribe(self, client: AsyncClient,
                         recording: _Recording) -> list[asyncio.Task[None]]:
        """Subscribe every watched object, then the marker, one after the other (the
        hub samples them in this order); each has its first sample when this returns."""
        tasks = []
        watched = [(name, w.cycle_ms, w.on_change) for w in self.watches for name in w.names]
        marker_ms = self._marker_ns(1_000_000) // 1_000_000
        for index, (name, cycle_ms, on_change) in enumerate(
                [*watched, (_MARKER, marker_ms, False)]):
            first = asyncio.Event()
            task = asyncio.create_task(recording.follow(
                client, index, name, cycle_ms, on_change, first,
                marker=index == len(watched)))
            tasks.append(task)
            waiting = asyncio.create_task(first.wait())
            await asyncio.wait((task, waiting), return_when=asyncio.FIRST_COMPLETED)
            waiting.cancel()
            if task.done():  # refused (no such object): say why
                for other in tasks:
                    other.cancel()
                task.result()
        return tasks

    def _marker_ns(self, cycle_ns: int) -> int:
        """The marker's cycle time: the greatest common divisor of the watched ones, so
        that every due cycle of a watched object is one of the marker's (0 ms: every
        cycle, ``cycle_ns``)."""
        divisor = 0
        for w in self.watches:
            divisor = math.gcd(divisor, w.cycle_ms)
        return cycle_ns if 0 in (w.cycle_ms for w in self.watches) else divisor * 1_000_000

    async def _run_to_end(self, client: AsyncClient, channel: int) -> None:
        """Wait until the program has ended; on the step clock grant the cycles."""
        if not self.stepping:
            await client.wait_program(channel)
            return
        while await client.read(f"ch{channel}.mc_active_state_r") in _RUNNING:
            await client.write("cnc_cycle_step_w", STEP_CHUNK_CYCLES)


_RUNNING = (ChannelState.ACTIVE, ChannelState.HOLD)


def _last_on_grid(time_ns: int, period_ns: int) -> int:
    return time_ns - time_ns % period_ns


class _Recording:
    """The samples as they come, by subscription."""

    def __init__(self, cycle_ns: int) -> None:
        self.cycle_ns = cycle_ns
        self._rows: list[tuple[int, int, str, Any]] = []  # kernel ns, watch index, name, value
        self._firsts: list[int] = []
        self._marker_ns = -1  # the newest marker sample's kernel time
        self._marker_seen = asyncio.Event()
        self.lost = 0  # samples missing between sequence numbers

    async def follow(self, client: AsyncClient, index: int, name: str, cycle_ms: int,
                     on_change: bool, first: asyncio.Event, marker: bool) -> None:
        samples = client.subscribe(name, on_change=on_change, cycle_ms=cycle_ms,
                                   buffer_samples=None)  # the service holds; so does this
        sequence = 0
        async with contextlib.aclosing(samples):
            async for sample in samples:
                if sample.sequence != sequence + 1:  # the service drops none: the client did
                    self.lost += sample.sequence - sequence - 1
                sequence = sample.sequence
                kernel_ns = self._kernel_ns(sample.timestamp)
                if not first.is_set():
                    self._firsts.append(kernel_ns)
                    first.set()
                if marker:
                    self._marker_ns = kernel_ns
                    self._marker_seen.set()
                else:
                    self._rows.append((kernel_ns, index, name, sample.value))

    def _kernel_ns(self, stamp: datetime) -> int:
        """The kernel time a repeatable sample carries, on the cycle grid (the stamp
        has microseconds)."""
        delta = stamp - _KERNEL_EPOCH
        us = (delta.days * 86_400 + delta.seconds) * 1_000_000 + delta.microseconds
        return round(us * 1000 / self.cycle_ns) * self.cycle_ns

    def start_ns(self) -> int:
        """The kernel time every first sample was taken at: the kernel rested."""
        if len(set(self._firsts)) != 1:
            raise TraceError(
                f"the first samples were taken at several kernel times ({sorted(set(self._firsts))} "
                "ns): the kernel did not rest while the recorder subscribed; does the service run "
                "with --samples repeatable, and is nothing else running?")
        return self._firsts[0]

    async def wait_marker(self, due_ns: int, start_ns: int) -> None:
        """Wait until the marker's sample of ``due_ns`` has come (every sample up to it
        has then come too); nothing to wait for at or before ``start_ns``."""
        while due_ns > start_ns and self._marker_ns < due_ns:
            self._marker_seen.clear()
            await self._marker_seen.wait()

    def rows(self, end_ns: int) -> list[TraceRow]:
        """The rows up to ``end_ns``, by kernel time, then in the order watched;
        ``TraceError`` when samples were lost on the way (a gap in a sequence)."""
        if self.lost:
            raise TraceError(
                f"{self.lost} samples did not reach the recorder (gaps in their sequence "
                "numbers; the client library keeps 1000 per subscription): watch fewer "
                "objects or with a longer cycle_ms")
        kept = sorted((r for r in self._rows if r[0] <= end_ns), key=lambda r: r[:2])
        return [TraceRow(kernel_ns, name, value) for kernel_ns, _, name, value in kept]
