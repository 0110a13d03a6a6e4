"""The baseline: a raw pyzmq ROUTER that echoes each frame with a reply of our shape."""

from __future__ import annotations

import msgpack
import zmq


def serve_echo(port_queue, ready) -> None:  # runs in a second process
    """Bind a free port, report it, then answer forever: no dispatch, no lookup."""
    ctx = zmq.Context()
    sock = ctx.socket(zmq.ROUTER)
    port = sock.bind_to_random_port("tcp://127.0.0.1")
    port_queue.put(f"tcp://127.0.0.1:{port}")
    data = b"\x00\x00\x00\x00"
    while True:
        identity, raw = sock.recv_multipart()
        request = msgpack.unpackb(raw)
        sock.send_multipart([identity, msgpack.packb([request[0], request[1], 0, data])])
