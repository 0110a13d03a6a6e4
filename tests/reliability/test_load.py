"""Load: 50 concurrent clients, each thousands of requests on its own objects.

Half the clients are the library's ``AsyncClient``; the other half are audited raw
DEALER clients that record every frame they receive, so that a reply that comes twice,
or one that nobody asked for, is counted (``AsyncClient`` drops those silently). All run
in one asyncio loop in this process, against one service.

Each round of a client: a handle-by-name read whose answer depends on the name asked
(a misrouted reply carries another handle), concurrently with a write of a value that
encodes (client, round) to an object the client holds for that moment, and the read-back
of that object, which must return the value written. The writable objects that no
program uses are few (ten), so the five clients sharing one take turns (a lock per
object in this process): while a client holds it, nobody else writes it, and the read
after the acknowledged write must see exactly its value.
"""

from __future__ import annotations

import asyncio
import itertools
import math
import struct
import time
from dataclasses import dataclass, field

import msgpack
import pytest
import zmq
import zmq.asyncio

from cnc_objects.clients import AsyncClient, ObjectInfo
from cnc_objects.protocol.constants import ReservedIndexGroup as RIG
from cnc_objects.protocol.datatypes import STRING_ENCODING
from cnc_objects.protocol.frames import ReadRequest, ReadWriteRequest, WriteRequest
from cnc_objects.testing import ServiceProcess, serving
from tests.reliability import figures
from tests.reliability.health import assert_well, vitals
from tests.reliability.scale import Scale
from tests.support.resources import rss_kib

REQUEST_TIMEOUT_S = 30.0  # one request under full load on a busy 2-core machine
NODE = "tests/reliability/test_load.py"
#: Writable objects no program or PLC logic reads while nothing runs: what the load
#: clients write, with the object that reads the value back (the same one when "rw").
OWNED = [
    ("ch1.syn_chk.errors_total", None),
    ("ch2.syn_chk.errors_total", None),
    ("ch1.syn_chk.errors_per_block", None),
    ("ch2.syn_chk.errors_per_block", None),
    ("gpCh[0].contour_lookahead.request.start_position", None),
    ("gpCh[1].contour_lookahead.request.start_position", None),
    ("gpCh[0].contour_lookahead.request.length", None),
    ("gpCh[1].contour_lookahead.request.length", None),
    ("ch1.mc_command_feed_override_w", "ch1.mc_command_feed_override_r"),
    ("ch2.mc_command_feed_override_w", "ch2.mc_command_feed_override_r"),
]
FEED_OVERRIDE_MAX = 1000  # 0.1 %: 100 %


@dataclass
class Target:
    """One shared writable object: where it is, how to encode a (client, round) value."""

    write: ObjectInfo
    read: ObjectInfo
    lock: asyncio.Lock = field(default_factory=asyncio.Lock)

    def value(self, client: int, round_: int) -> int | float:
        """A value unique to (client, round) as far as the type allows."""
        if self.write.type == "REAL64":
            return client * 1_000_000.0 + round_ + 0.25
        if "feed_override" in self.write.name:
            return (client * 37 + round_) % (FEED_OVERRIDE_MAX + 1)
        return (client * 1000 + round_) % 0x10000

    def encode(self, value: int | float) -> bytes:
        return struct.pack("<d" if self.write.type == "REAL64" else "<H", value)


@dataclass
class Tally:
    """What all clients saw."""

    requests: int = 0
    writes: int = 0
    latencies_s: list[float] = field(default_factory=list)
    wrong_values: list[str] = field(default_factory=list)
    duplicates: int = 0
    unexpected: int = 0


class AuditedClient:
    """A raw DEALER client on the loop that matches replies by invoke id and counts
    every reply that comes twice or was never asked for."""

    def __init__(self, context: zmq.asyncio.Context, endpoint: str, tally: Tally) -> None:
        self.sock = context.socket(zmq.DEALER)
        self.sock.setsockopt(zmq.LINGER, 0)
        self.sock.connect(endpoint)
        self.tally = tally
        self._ids = itertools.count(1)
        self._pending: dict[int, asyncio.Future[list]] = {}
        self._answered: set[int] = set()
        self._reader = asyncio.get_running_loop().create_task(self._read(), name="audited reader")

    async def close(self) -> None:
        self._reader.cancel()
        try:
            await self._reader
        except asyncio.CancelledError:
            pass
        self.sock.close(linger=0)

    async def _read(self) -> None:
        while True:
            reply = msgpack.unpackb(await self.sock.recv(), raw=False)
            invoke_id = reply[0]
            future = self._pending.pop(invoke_id, None)
            if future is not None:
                self._answered.add(invoke_id)
                future.set_result(reply)
            elif invoke_id in self._answered:
                self.tally.duplicates += 1
            elif invoke_id != 0:  # 0: a notification (none are opened here)
                self.tally.unexpected += 1

    async def call(self, request_type: type, *fields: object) -> list:
        """Send a request; its reply (``AssertionError`` on an error code)."""
        invoke_id = next(self._ids)
        future = asyncio.get_running_loop().create_future()
        self._pending[invoke_id] = future
        await self.sock.send(request_type(invoke_id, *fields).encode())
        reply = await asyncio.wait_for(future, REQUEST_TIMEOUT_S)
        assert reply[1] == request_type.COMMAND and reply[2] == 0, reply
        return reply


async def timed(tally: Tally, request: object) -> object:
    """Await ``request``, adding its latency and count to the tally."""
    started = time.perf_counter()
    result = await request  # type: ignore[misc]
    tally.latencies_s.append(time.perf_counter() - started)
    tally.requests += 1
    return result


def name_bytes(info: ObjectInfo) -> bytes:
    return info.name.encode(STRING_ENCODING) + b"\x00"


async def library_client(k: int, endpoint: str, targets: list[Target], names: list[ObjectInfo],
                         handles: dict[str, int], rounds: int, tally: Tally) -> None:
    """Client ``k`` as an ``AsyncClient``: its rounds, checking every answer."""
    target = targets[k % len(targets)]
    async with AsyncClient(endpoint, timeout_s=REQUEST_TIMEOUT_S) as client:
        for r in range(rounds):
            info = names[(k * 7919 + r) % len(names)]

            async def handle() -> None:
                raw = await timed(tally, client.read_write_raw(
                    info.port, RIG.SYM_HANDLE_BY_NAME, 0, name_bytes(info), 4))
                if int.from_bytes(raw, "little") != handles[info.name]:
                    tally.wrong_values.append(f"client {k}: handle of {info.name}: {raw!r}")

            async def write_and_read_back() -> None:
                value = target.value(k, r)
                async with target.lock:
                    await timed(tally, client.write(target.write.name, value))
                    tally.writes += 1
                    back = await timed(tally, client.read(target.read.name))
                if back != value:
                    tally.wrong_values.append(f"client {k} round {r}: wrote {value} to "
                                              f"{target.write.name}, read back {back}")

            await asyncio.gather(handle(), write_and_read_back())


async def audited_client(k: int, context: zmq.asyncio.Context, endpoint: str,
                         targets: list[Target], names: list[ObjectInfo],
                         handles: dict[str, int], rounds: int, tally: Tally) -> None:
    """Client ``k`` on a raw audited socket: the same rounds, frame by frame."""
    target = targets[k % len(targets)]
    w, rb = target.write, target.read
    client = AuditedClient(context, endpoint, tally)
    try:
        for r in range(rounds):
            info = names[(k * 7919 + r) % len(names)]

            async def handle() -> None:
                reply = await timed(tally, client.call(
                    ReadWriteRequest, info.port, RIG.SYM_HANDLE_BY_NAME, 0, 4, name_bytes(info)))
                if int.from_bytes(reply[3], "little") != handles[info.name]:
                    tally.wrong_values.append(f"client {k}: handle of {info.name}: {reply}")

            async def write_and_read_back() -> None:
                data = target.encode(target.value(k, r))
                async with target.lock:
                    await timed(tally, client.call(WriteRequest, w.port, w.group, w.offset, data))
                    tally.writes += 1
                    reply = await timed(tally, client.call(
                        ReadRequest, rb.port, rb.group, rb.offset, rb.length))
                if reply[3] != data:
                    tally.wrong_values.append(f"client {k} round {r}: wrote {data!r} to "
                                              f"{w.name}, read back {reply[3]!r}")

            await asyncio.gather(handle(), write_and_read_back())
    finally:
        await client.close()


@pytest.fixture(scope="module")
def service() -> ServiceProcess:
    """One service for the load test (virtual clock)."""
    with serving() as running:
        yield running


async def test_fifty_clients_get_every_reply_once_and_read_their_writes_back(
    service: ServiceProcess, run_scale: Scale
) -> None:
    async with AsyncClient(service.endpoint, timeout_s=REQUEST_TIMEOUT_S) as client:
        catalog = {o.name: o for o in await client.browse("*")}
        before_values = {w: await client.read(r or w) for w, r in OWNED}
        handles_raw = {name: await client.read_write_raw(
            info.port, RIG.SYM_HANDLE_BY_NAME, 0, name_bytes(info), 4)
            for name, info in catalog.items()}
    handles = {name: int.from_bytes(raw, "little") for name, raw in handles_raw.items()}
    assert len(set(handles.values())) == len(handles), "handles must differ per object"
    targets = [Target(catalog[w], catalog[r or w]) for w, r in OWNED]
    names = sorted(catalog.values(), key=lambda o: o.name)
    before = vitals(service.endpoint)
    rss_start_kib = rss_kib(service.process.pid)
    tally = Tally()
    clients, rounds = run_scale.load_clients, run_scale.load_rounds
    context = zmq.asyncio.Context()
    started = time.perf_counter()
    try:
        async with asyncio.TaskGroup() as group:
            for k in range(clients):
                if k % 2:
                    group.create_task(audited_client(
                        k, context, service.endpoint, targets, names, handles, rounds, tally),
                        name=f"audited client {k}")
                else:
                    group.create_task(library_client(
                        k, service.endpoint, targets, names, handles, rounds, tally),
                        name=f"library client {k}")
    finally:
        context.destroy(linger=0)
    elapsed_s = time.perf_counter() - started
    rss_end_kib = rss_kib(service.process.pid)

    # put the objects back as they were
    async with AsyncClient(service.endpoint, timeout_s=REQUEST_TIMEOUT_S) as client:
        for (name, _), value in zip(OWNED, before_values.values()):
            await client.write(name, value)
    assert_well(service, before.tick, before)

    latencies = sorted(tally.latencies_s)
    p50_ms = latencies[len(latencies) // 2] * 1000
    p99_ms = latencies[math.ceil(len(latencies) * 0.99) - 1] * 1000
    throughput = tally.requests / elapsed_s
    lost = clients * rounds * 3 - tally.requests  # each request is awaited: none can be
    print(f"\nload: {clients} clients x {rounds} rounds: {tally.requests} requests "
          f"({tally.writes} acknowledged writes, each read back) in {elapsed_s:.1f} s = "
          f"{throughput:.0f} requests/s; latency p50 {p50_ms:.2f} ms, p99 {p99_ms:.2f} ms, "
          f"max {latencies[-1] * 1000:.1f} ms; lost {lost}, duplicates {tally.duplicates}, "
          f"unexpected {tally.unexpected}, wrong values {len(tally.wrong_values)}; "
          f"RSS {rss_start_kib} -> {rss_end_kib} KiB")
    figures.record("load: clients x rounds, requests",
                   f"{clients} x {rounds}, {tally.requests} ({tally.writes} writes read back)",
                   NODE)
    figures.record("load: throughput, latency p50 / p99",
                   f"{throughput:.0f} requests/s, {p50_ms:.2f} / {p99_ms:.2f} ms", NODE)
    figures.record("load: lost / duplicated / misrouted replies, wrong read-backs",
                   f"{lost} / {tally.duplicates} / {tally.unexpected} / {len(tally.wrong_values)}",
                   NODE)
    assert lost == 0
    assert tally.duplicates == 0 and tally.unexpected == 0
    assert not tally.wrong_values, tally.wrong_values[:10]
