"""The notification limit used up by one client, and another client's reads meanwhile:
what the fairness test (tests/reliability/test_notification_fairness.py) and the bench
(``make bench``, part ``fairness``) measure.

``notification_load`` runs ``cyclic_subscribers`` in a process of its own (its reading
must not share this process' GIL with the reads measured) and waits until every
notification is acknowledged; ``read_latencies_s`` times plain reads on a connection of
their own, one at a time, as an HMI polls.
"""

from __future__ import annotations

import contextlib
import socket
import struct
import subprocess
import sys
import time
from collections.abc import Iterator

import msgpack
import zmq

from tests.support.cyclic_subscribers import AMS_FRAME, ads_frame
from tests.support.service import ROOT

SUBSCRIBE_TIMEOUT_S = 120.0  # 20 000 AddNotifications on a loaded 2-core machine
READ_TIMEOUT_S = 10.0
READ = (553, 0x120101, 0x3002, 4)  # ch1.mc_active_state_r


@contextlib.contextmanager
def notification_load(endpoint: str, sockets: int, per_socket: int,
                      cycle_ms: int = 1) -> Iterator[list[int]]:
    """``sockets`` clients of ``per_socket`` cyclic notifications each, every sample
    read; yields a list that holds the count of samples read once the block is left.
    ``endpoint`` is a ZeroMQ endpoint, or ``ads:HOST:PORT:NETID`` for ADS connections
    (``ads_target``)."""
    child = subprocess.Popen(
        [sys.executable, "-m", "tests.support.cyclic_subscribers", endpoint, str(sockets),
         str(per_socket), str(cycle_ms)],
        cwd=ROOT, stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
    samples: list[int] = []
    try:
        assert child.stdout is not None and child.stdin is not None
        line = _line_within(child, SUBSCRIBE_TIMEOUT_S)
        assert line.startswith("subscribed"), f"the subscribers said {line!r}"
        yield samples
        child.stdin.close()
        line = _line_within(child, READ_TIMEOUT_S)
        if line.startswith("samples"):
            samples.append(int(line.split()[1]))
    finally:
        child.kill()
        child.wait()


def ads_target(address: tuple[str, int], net_id: str) -> str:
    """The ``notification_load`` endpoint of an ADS server."""
    return f"ads:{address[0]}:{address[1]}:{net_id}"


def _line_within(child: subprocess.Popen[str], timeout_s: float) -> str:
    """The child's next line of output, or AssertionError after ``timeout_s``."""
    assert child.stdout is not None
    poller = zmq.Poller()
    poller.register(child.stdout.fileno(), zmq.POLLIN)
    assert poller.poll(int(timeout_s * 1000)), f"no line from the subscribers in {timeout_s} s"
    return child.stdout.readline().strip()


def read_latencies_s(endpoint: str, count: int) -> list[float]:
    """Latency of each of ``count`` reads (one at a time) on a fresh connection."""
    context = zmq.Context()
    sock = context.socket(zmq.DEALER)
    sock.setsockopt(zmq.LINGER, 0)
    sock.connect(endpoint)
    latencies = []
    try:
        for invoke_id in range(1, count + 1):
            start = time.perf_counter()
            sock.send(msgpack.packb([invoke_id, 2, *READ]))
            assert sock.poll(int(READ_TIMEOUT_S * 1000)), f"read {invoke_id}: no reply"
            reply = msgpack.unpackb(sock.recv())
            latencies.append(time.perf_counter() - start)
            assert reply[0] == invoke_id and reply[2] == 0, reply
    finally:
        sock.close(linger=0)
        context.term()
    return latencies


def ads_read_latencies_s(address: tuple[str, int], net_id: str, count: int) -> list[float]:
    """Latency of each of ``count`` ADS reads (one at a time) on a fresh connection."""
    target = bytes(int(p) for p in net_id.split("."))
    port, group, offset, length = READ
    latencies = []
    with socket.create_connection(address, timeout=READ_TIMEOUT_S) as sock:
        buffer = bytearray()
        for invoke_id in range(1, count + 1):
            start = time.perf_counter()
            sock.sendall(ads_frame(target, port, 2, invoke_id,
                                   struct.pack("<3I", group, offset, length)))
            while True:
                size = 6 + int.from_bytes(buffer[2:6], "little") if len(buffer) >= 6 else 0
                if size and len(buffer) >= size:
                    head = AMS_FRAME.unpack_from(buffer)
                    del buffer[:size]
                    if head[10] == invoke_id:
                        break
                    continue
                chunk = sock.recv(65536)
                assert chunk, "the service closed the ADS connection"
                buffer += chunk
            latencies.append(time.perf_counter() - start)
    return latencies


def p99(values: list[float]) -> float:
    """The 99th percentile of ``values``."""
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, int(len(ordered) * 0.99))]
