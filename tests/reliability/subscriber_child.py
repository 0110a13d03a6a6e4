"""A client process that opens many notifications and then floods the service with
requests it never waits for, until it is killed (test_killed_client.py).

    python subscriber_child.py ENDPOINT SOCKETS PER_SOCKET PORT GROUP OFFSET LENGTH flood|idle

Opens SOCKETS DEALER connections (each a client of its own to the service), opens
PER_SOCKET on-change notifications on each (of the object at PORT/GROUP/OFFSET, LENGTH
bytes; checked once a second), prints ``subscribed N`` once every one is acknowledged,
then (``flood``) sends reads on every connection without reading replies, or (``idle``)
does nothing more. Runs at most ``LIFETIME_S`` (it is meant to be killed long before);
standard library and pyzmq only.
"""

from __future__ import annotations

import sys
import time

import msgpack
import zmq

IN_FLIGHT = 200  # AddNotification requests sent ahead of their replies
LIFETIME_S = 120.0  # a child nobody killed ends by itself
ON_CHANGE, CHECK_MS = 4, 1000


def main() -> None:
    endpoint, sockets, per_socket = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
    port, group, offset, length = (int(a, 0) for a in sys.argv[4:8])
    flood = sys.argv[8] == "flood"
    context = zmq.Context()
    opened = []
    for _ in range(sockets):
        sock = context.socket(zmq.DEALER)
        sock.setsockopt(zmq.LINGER, 0)
        sock.connect(endpoint)
        sent = done = 0
        while done < per_socket:
            while sent < per_socket and sent - done < IN_FLIGHT:
                sent += 1
                sock.send(msgpack.packb([sent, 6, port, group, offset, length, ON_CHANGE, 0,
                                         CHECK_MS]))
            reply = msgpack.unpackb(sock.recv())
            if reply[0] == 0:
                continue  # a sample
            if reply[2] != 0:
                sys.exit(f"AddNotification {reply[0]} refused: {reply}")
            done += 1
        opened.append(sock)
    print(f"subscribed {sockets * per_socket}", flush=True)
    deadline = time.monotonic() + LIFETIME_S
    invoke_id = 1_000_000
    while time.monotonic() < deadline and not flood:
        time.sleep(1.0)  # idle: waiting to be killed, nothing else
    while time.monotonic() < deadline:  # mid-flight: requests whose replies nobody reads
        for sock in opened:
            invoke_id += 1
            try:
                sock.send(msgpack.packb([invoke_id, 2, port, group, offset, length]), zmq.NOBLOCK)
            except zmq.Again:
                time.sleep(0.01)  # the queue is full: the service has not read them yet


if __name__ == "__main__":
    main()
