"""Watched at event speed (issue 37, docs/kernel.md "Watched at 200x").

A loop behind the event-speed kernel loses no due cycle: many subscriptions due every
kernel cycle make each sampling pass cost more than the kernel's cruising cycles, so the
kernel gets ``PASSES_PENDING_MAX`` due cycles ahead of the loop. The event-speed clock
then waits until the loop has sampled most of them instead of stepping single cycles
that push the oldest kept ones out: with ``samples = "latest"`` too, a subscription sees
every due cycle of a run, in order.

The due cycles a bulk runs to wake the loop in batches (``WAKE_BATCH``), not one by one:
their samples come in few frames, and every one of them comes.
"""

from __future__ import annotations

import asyncio
import contextlib
import struct
from collections.abc import AsyncIterator
from typing import Any

import zmq

from cnc_objects.clients import AsyncClient, Client
from cnc_objects.protocol.constants import AdsCommand, TransmissionMode
from cnc_objects.protocol.frames import Notification, Response, decode_incoming, encode_request
from cnc_objects.testing import serving

CLOCK = "cnc_kernel_time_r"  # s; changes every kernel cycle (1 ms)
LOAD = 200  # further on-change subscriptions at 1 ms: a pass costs more than a cycle
MOVE = "G91 G1 X10 F600"  # one second of kernel time, cruising (run in bulk)
WATCHED_S = 1.2  # the move and a little rest after it


async def test_every_due_cycle_is_sampled_while_the_loop_is_behind() -> None:
    """Every kernel cycle of a move is due; each one's kernel time is sampled, 1 ms
    after the one before, however far behind the loop fell."""
    with serving("--clock", "virtual") as service:
        async with AsyncClient(service.endpoint, timeout_s=60) as c, \
                AsyncClient(service.endpoint, timeout_s=60) as load:
            names = [o.name for o in await load.browse("ch1.*") if "r" in o.access][:LOAD]
            async with contextlib.AsyncExitStack() as stack:
                heavy = [await stack.enter_async_context(
                    contextlib.aclosing(load.subscribe(n, cycle_ms=0))) for n in names]
                await asyncio.gather(*(anext(s) for s in heavy))  # all of them open
                clock: AsyncIterator[Any] = await stack.enter_async_context(
                    contextlib.aclosing(c.subscribe(CLOCK, cycle_ms=0, buffer_samples=None)))
                start_s = (await anext(clock)).value
                await c.mdi(MOVE)
                times_s = [start_s]
                while times_s[-1] < start_s + WATCHED_S:
                    times_s.append((await asyncio.wait_for(anext(clock), 30)).value)
    steps_us = {round((b - a) * 1e6) for a, b in zip(times_s, times_s[1:])}
    assert steps_us == {1000}, sorted(steps_us)[:10]


BATCH_MOVE = "G91 G1 X50 F600"  # five seconds of kernel time, cruising
BATCH_MOVE_S = 5.0
BATCH_CYCLE_MS = 10


def test_due_cycles_of_a_bulk_come_in_batches_and_all_of_them() -> None:
    """One on-change subscription of the kernel time (a new value every due cycle)
    while a move runs in bulk: a sample for every 10 ms of the move, and many samples to
    a frame (one wake-up of the loop samples them all)."""
    with serving("--clock", "virtual") as service, Client(service.endpoint) as c:
        info = c.describe(CLOCK)
        reader = zmq.Context.instance().socket(zmq.DEALER)
        reader.setsockopt(zmq.LINGER, 0)
        reader.setsockopt(zmq.RCVTIMEO, 30_000)
        reader.connect(service.endpoint)
        try:
            reader.send(encode_request(
                1, AdsCommand.ADD_DEVICE_NOTIFICATION, info.port,
                (info.group, info.offset, info.length,
                 int(TransmissionMode.SERVER_ON_CHANGE), 0, BATCH_CYCLE_MS)))
            handle = None
            while handle is None:  # the reply (a first sample may come before it)
                message = decode_incoming(reader.recv())
                if isinstance(message, Response):
                    assert message.result == 0, message
                    handle = message.fields[0]
            start_s = c.read(CLOCK)
            c.mdi(BATCH_MOVE)
            frames: list[list[float]] = []  # the kernel times of each frame's samples
            last_s = 0.0
            while last_s < start_s + BATCH_MOVE_S:
                message = decode_incoming(reader.recv())
                if not isinstance(message, Notification):
                    continue
                times_s = [struct.unpack("<d", s.data)[0] for s in message.samples
                           if s.handle == handle]
                if times_s:
                    frames.append(times_s)
                    last_s = times_s[-1]
        finally:
            reader.close()
    # the move's due cycles: from the first after START on, every 10 ms, none missing
    moving = [t for f in frames for t in f if t > start_s + 0.1]
    moving_ms = [round(t * 1000) for t in moving]
    assert moving_ms == list(range(moving_ms[0], moving_ms[-1] + 1, BATCH_CYCLE_MS))
    in_move = [f for f in frames if f[0] > start_s + 0.1]
    samples_per_frame = sum(len(f) for f in in_move) / len(in_move)
    # about WAKE_BATCH (16) and more: the samples of the due cycles kept until the loop
    # woke, and of those the bulk added while it sampled (one by one: about 6)
    assert samples_per_frame >= 12, (samples_per_frame, len(in_move))
