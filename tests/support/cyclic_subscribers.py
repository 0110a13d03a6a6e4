"""A client process that holds many cyclic notifications and reads every sample, as a
client using up the service's notification limit would (the fairness test and bench).

    python -m tests.support.cyclic_subscribers ENDPOINT SOCKETS PER_SOCKET CYCLE_MS

Opens SOCKETS DEALER connections (each a client of its own to the service), opens
PER_SOCKET cyclic notifications on each (every CYCLE_MS, over the objects of
``WATCHED`` in turn), prints ``subscribed N`` once every one is acknowledged, then reads
every sample until stdin closes (or ``LIFETIME_S``) and prints ``samples N``.
Standard library and pyzmq only.
"""

from __future__ import annotations

import selectors
import sys
import time

import msgpack
import zmq

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


def main() -> None:
    endpoint, sockets, per_socket, cycle_ms = sys.argv[1], *map(int, sys.argv[2:5])
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
