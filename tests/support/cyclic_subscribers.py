"""A client process that holds many cyclic notifications and reads every sample, as a
client using up the service's notification limit would (the fairness test and bench).

    python -m tests.support.cyclic_subscribers ENDPOINT SOCKETS PER_SOCKET CYCLE_MS
    python -m tests.support.cyclic_subscribers ads:HOST:PORT:NETID SOCKETS PER_SOCKET CYCLE_MS

Opens SOCKETS DEALER connections (or ADS TCP connections, each a client of its own to
the service), opens
PER_SOCKET cyclic notifications on each (every CYCLE_MS, over the objects of
``WATCHED`` in turn), prints ``subscribed N`` once every one is acknowledged, then reads
every sample until stdin closes (or ``LIFETIME_S``) and prints ``samples N``.
Standard library and pyzmq only.
"""

from __future__ import annotations

import selectors
import socket
import struct
import sys
import time

import msgpack
import zmq

#: AMS/TCP and AMS header of a request (the layout of protocol/ams.py, kept here so that
#: this process needs the standard library and pyzmq only).
AMS_FRAME = struct.Struct("<HI6sH6sHHHIII")
ADS_SOURCE = bytes([127, 0, 0, 1, 9, 9])
ADS_ADD_NOTIFICATION = 6

IN_FLIGHT = 200  # AddNotification requests sent ahead of their replies
LIFETIME_S = 300.0  # a child nobody stopped ends by itself
CYCLIC = 3  # ADS transmission mode: server cycle
#: (port, group, offset, length) of objects that change every cycle or stay: a realistic
#: mix (an HMI watches positions, counters, states).
WATCHED = [
    (553, 0x120100, 0x1011, 4),  # cnc_tick_counter_r
    (553, 0x120101, 0xA, 2),  # ch1.mc_command_feed_override_r
    (553, 0x120101, 0x3002, 4),  # ch1.mc_active_state_r
    (551, 0x121301, 0x10002, 4),  # ch1.ax1.command_position_acs
    (553, 0x120102, 0x3005, 84),  # ch2.mc_active_program_name_r
]


def subscribe(sock: zmq.Socket, count: int, cycle_ms: int, first: int) -> None:
    """Open ``count`` cyclic notifications on ``sock``; objects from ``first`` on."""
    sent = done = 0
    while done < count:
        while sent < count and sent - done < IN_FLIGHT:
            port, group, offset, length = WATCHED[(first + sent) % len(WATCHED)]
            sent += 1
            sock.send(msgpack.packb([sent, 6, port, group, offset, length, CYCLIC, 0,
                                     cycle_ms]))
        reply = msgpack.unpackb(sock.recv())
        if reply[0] == 0:
            continue  # a sample
        if reply[2] != 0:
            sys.exit(f"AddNotification {reply[0]} refused: {reply}")
        done += 1


def ads_frame(net_id: bytes, port: int, command: int, invoke_id: int, data: bytes) -> bytes:
    """An AMS/TCP request frame to ``net_id``:``port``."""
    return AMS_FRAME.pack(0, 32 + len(data), net_id, port, ADS_SOURCE, 30000, command, 4,
                          len(data), 0, invoke_id) + data


def ads_subscribe(sock: socket.socket, net_id: bytes, count: int, cycle_ms: int,
                  first: int) -> None:
    """Open ``count`` cyclic notifications on an ADS connection (all sent, then every
    response read; samples in between are skipped)."""
    for k in range(count):
        port, group, offset, length = WATCHED[(first + k) % len(WATCHED)]
        data = struct.pack("<6I16x", group, offset, length, CYCLIC, 0, cycle_ms * 10_000)
        sock.sendall(ads_frame(net_id, port, ADS_ADD_NOTIFICATION, k + 1, data))
    buffer, done = bytearray(), 0
    while done < count:
        chunk = sock.recv(1 << 20)
        if not chunk:
            sys.exit("the service closed an ADS connection")
        buffer += chunk
        while len(buffer) >= 6 and len(buffer) >= 6 + int.from_bytes(buffer[2:6], "little"):
            size = 6 + int.from_bytes(buffer[2:6], "little")
            head = AMS_FRAME.unpack_from(buffer)
            if head[6] == ADS_ADD_NOTIFICATION:
                if int.from_bytes(buffer[38:42], "little"):
                    sys.exit(f"AddDeviceNotification refused: {bytes(buffer[38:42]).hex()}")
                done += 1
            del buffer[:size]


def ads_main(target: str, sockets: int, per_socket: int, cycle_ms: int) -> None:
    """The ADS form: every sample read (and dropped) as raw bytes."""
    host, port, net_id_text = target.split(":")
    net_id = bytes(int(p) for p in net_id_text.split("."))
    opened = []
    for k in range(sockets):
        sock = socket.create_connection((host, int(port)))
        ads_subscribe(sock, net_id, per_socket, cycle_ms, k)
        sock.setblocking(False)
        opened.append(sock)
    print(f"subscribed {sockets * per_socket}", flush=True)
    selector = selectors.DefaultSelector()
    for sock in opened:
        selector.register(sock, selectors.EVENT_READ)
    selector.register(sys.stdin, selectors.EVENT_READ)
    received, deadline = 0, time.monotonic() + LIFETIME_S
    while time.monotonic() < deadline:
        ready = selector.select(0.1)
        if any(key.fileobj is sys.stdin for key, _ in ready):
            break
        for key, _ in ready:
            try:
                while chunk := key.fileobj.recv(1 << 20):  # type: ignore[union-attr]
                    received += len(chunk)
            except BlockingIOError:
                pass
    print(f"samples {received // 16}", flush=True)  # about: 16 bytes a 4-byte sample


def main() -> None:
    endpoint, sockets, per_socket, cycle_ms = sys.argv[1], *map(int, sys.argv[2:5])
    if endpoint.startswith("ads:"):
        ads_main(endpoint.removeprefix("ads:"), sockets, per_socket, cycle_ms)
        return
    context = zmq.Context()
    opened = []
    for k in range(sockets):
        sock = context.socket(zmq.DEALER)
        sock.setsockopt(zmq.LINGER, 0)
        sock.connect(endpoint)
        subscribe(sock, per_socket, cycle_ms, k)
        opened.append(sock)
    print(f"subscribed {sockets * per_socket}", flush=True)
    poller = zmq.Poller()
    for sock in opened:
        poller.register(sock, zmq.POLLIN)
    stdin = selectors.DefaultSelector()
    stdin.register(sys.stdin, selectors.EVENT_READ)
    samples, deadline = 0, time.monotonic() + LIFETIME_S
    while time.monotonic() < deadline and not stdin.select(0):
        for sock, _ in poller.poll(100):
            while True:
                try:
                    frame = sock.recv(zmq.NOBLOCK)
                except zmq.Again:
                    break
                samples += len(msgpack.unpackb(frame)[3])
    print(f"samples {samples}", flush=True)


if __name__ == "__main__":
    main()
