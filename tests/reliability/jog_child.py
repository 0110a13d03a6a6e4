"""A client process that presses a jog key and then does nothing until it is killed
(test_jog_dead_man.py).

    python jog_child.py zmq ENDPOINT KEY
    python jog_child.py ads NET_ID IP LOCAL_NET_ID KEY

``zmq``: our ``Client`` over ZeroMQ; ``ads``: pyads (Beckhoff's AdsLib) over AMS/TCP,
writing the key by name on port 553. Prints ``pressed`` once the write is acknowledged,
then sleeps (at most ``LIFETIME_S``: it is meant to be killed long before), never
renewing the key.
"""

from __future__ import annotations

import sys
import time

LIFETIME_S = 120.0


def main() -> None:
    wire = sys.argv[1]
    if wire == "zmq":
        from cnc_objects.clients import Client

        endpoint, key = sys.argv[2], sys.argv[3]
        with Client(endpoint, timeout_s=20) as client:
            client.write(key, True)
            print("pressed", flush=True)
            time.sleep(LIFETIME_S)
        return
    import pyads

    net_id, ip, local_net_id, key = sys.argv[2:6]
    pyads.open_port()
    pyads.set_local_address(local_net_id)
    pyads.add_route(net_id, ip)
    connection = pyads.Connection(net_id, 553, ip)
    connection.open()
    connection.write_by_name(key, True, pyads.PLCTYPE_BOOL)
    print("pressed", flush=True)
    time.sleep(LIFETIME_S)


if __name__ == "__main__":
    main()
