"""Wrong OPC UA passwords and the event loop they share with the other front ends.

    .venv/bin/python -m bench.opcua_signin_probe [--pause-s S]

asyncua asks its user manager synchronously, on the event loop: each password check
(Argon2id, some 100 ms) stops every other request the loop serves meanwhile, the
service's ZeroMQ and ADS ones included. This probe runs asyncua's server secured by
``apply_security`` (loopback, a users file), one anonymous session reading a variable
in a loop, and ``ATTACKERS`` clients that sign in with wrong passwords for ``SECONDS``;
it prints the reader's latency (p50, p99, max), how many attempts were made and how many
were checked (hashed). ``--pause-s 0`` turns the pause after a wrong password off (the
figures without it); the default is ``FAILED_CHECK_PAUSE_S``.
"""

from __future__ import annotations

import argparse
import asyncio
import logging
import statistics
import tempfile
import time
from pathlib import Path

from asyncua import ua
from asyncua.client.client import Client
from asyncua.server.server import Server

from cnc_objects.protocol.role_passwords import RolePasswords, format_role_passwords
from cnc_objects.protocol.roles import Role
from cnc_objects.service.opcua import security
from cnc_objects.service.opcua.security import apply_security
from cnc_objects.service.opcua.security_config import OpcUaSecurity

SECONDS = 4.0
ATTACKERS = 4


async def _reader(url: str, node: ua.NodeId, stop: asyncio.Event, latencies_s: list[float]) -> None:
    async with Client(url, timeout=30) as client:
        variable = client.get_node(node)
        while not stop.is_set():
            started = time.perf_counter()
            await variable.read_value()
            latencies_s.append(time.perf_counter() - started)


async def _attacker(url: str, stop: asyncio.Event, attempts: list[int]) -> None:
    while not stop.is_set():
        client = Client(url, timeout=30)
        client.set_user("operator")
        client.set_password("a wrong guess")
        attempts[0] += 1
        try:
            await client.connect()
            await client.disconnect()
        except Exception:  # refused, as every attempt here must be
            client.disconnect_socket()


async def probe(pause_s: float) -> None:
    security.FAILED_CHECK_PAUSE_S = pause_s
    checked = [0]
    verify = RolePasswords.verify

    def counted(self: RolePasswords, role: Role, password: str) -> bool:
        checked[0] += 1
        return verify(self, role, password)

    RolePasswords.verify = counted  # type: ignore[method-assign]
    with tempfile.TemporaryDirectory() as scratch:
        users_file = Path(scratch) / "web-users.json"
        passwords = RolePasswords()
        passwords.set_password(Role.OPERATOR, "the right one")
        users_file.write_text(format_role_passwords(passwords), encoding="utf-8")
        server = Server()
        await server.init()
        server.set_endpoint("opc.tcp://127.0.0.1:0/probe/")
        namespace = await server.register_namespace("urn:probe")
        answer = await server.nodes.objects.add_variable(namespace, "Answer", 42)
        await apply_security(server, OpcUaSecurity(users_file=str(users_file)), "127.0.0.1")
        await server.start()
        assert server.bserver is not None
        url = f"opc.tcp://127.0.0.1:{server.bserver.port}/probe/"
        stop = asyncio.Event()
        latencies_s: list[float] = []
        attempts = [0]
        try:
            reader = asyncio.create_task(_reader(url, answer.nodeid, stop, latencies_s))
            while not latencies_s:
                await asyncio.sleep(0.01)
            latencies_s.clear()
            attackers = [asyncio.create_task(_attacker(url, stop, attempts))
                         for _ in range(ATTACKERS)]
            await asyncio.sleep(SECONDS)
            stop.set()
            await asyncio.gather(reader, *attackers)
        finally:
            await server.stop()
    ms = sorted(1000 * s for s in latencies_s)
    print(f"pause {pause_s:.1f} s: reader p50 {statistics.median(ms):.1f} ms, "
          f"p99 {ms[int(0.99 * (len(ms) - 1))]:.1f} ms, max {ms[-1]:.1f} ms over {len(ms)} "
          f"reads; {attempts[0]} wrong sign-ins in {SECONDS:.0f} s, {checked[0]} checked")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--pause-s", type=float, default=security.FAILED_CHECK_PAUSE_S)
    logging.disable(logging.CRITICAL)  # every refusal is logged; the figures are the point
    asyncio.run(probe(parser.parse_args().pause_s))


if __name__ == "__main__":
    main()
