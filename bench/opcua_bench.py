"""``make bench`` OPC UA part (issue 40).

Reads: asyncua's client reading 100 nodes per Read call, against asyncua's own server
serving 100 static variables (a second process: the baseline), then against the real
``cnc-service`` (realtime clock, 1 ms cycle) reading 100 bound CncInterface variables.
The ratio is taken within each run (baseline right before the service), its median
printed. Target: >= 0.8 of the baseline.

Data changes and the kernel cycle with OPC UA sessions subscribed: ``main`` ends with
``opcua_subscription_bench``.

Start-up: from spawning ``cnc-service --clock virtual`` to its last start-up line, with
``--opcua off``, with OPC UA and no address space cache (cold), and with the cache the
cold start wrote (warm); medians. Target: < 3 s.

    python -m bench.opcua_bench [RUNS]      (or python -m bench --part opcua)
"""

from __future__ import annotations

import asyncio
import multiprocessing as mp
import os
import shutil
import statistics
import sys
import tempfile
import time

from asyncua import Client, Server, ua

from cnc_objects.testing.process import start_service

from .opcua_subscription_bench import double_variables

NODES = 100
CALLS = 300  # Read calls per measurement
CNC_URI = "http://opcfoundation.org/UA/CNC"


def _serve_static(ready: mp.Queue) -> None:  # type: ignore[type-arg]
    """A bare asyncua server with ``NODES`` static Double variables (second process)."""

    async def main() -> None:
        server = Server()
        await server.init()
        server.set_endpoint("opc.tcp://127.0.0.1:0")
        server.set_security_policy([ua.SecurityPolicyType.NoSecurity])
        folder = await server.nodes.objects.add_folder(2, "Static")
        ids = []
        for k in range(NODES):
            var = await folder.add_variable(2, f"v{k}", float(k))
            ids.append(var.nodeid.to_string())
        await server.start()
        ready.put((server.bserver.port, ids))  # type: ignore[union-attr]
        await asyncio.Event().wait()

    asyncio.run(main())


async def _reads_per_s(url: str, ids: list[str]) -> float:
    async with Client(url, timeout=30) as client:
        nodes = [ua.NodeId.from_string(i) for i in ids]
        for _ in range(20):  # warm up
            await client.uaclient.read_attributes(nodes, ua.AttributeIds.Value)
        began = time.perf_counter()
        for _ in range(CALLS):
            results = await client.uaclient.read_attributes(nodes, ua.AttributeIds.Value)
        elapsed = time.perf_counter() - began
        assert all(r.StatusCode.is_good() for r in results)
    return CALLS * NODES / elapsed


async def _bound_ids(url: str) -> list[str]:
    """``NODES`` Double variables of the CncInterface bound to objects (channel, axis and
    position members: the baseline's type, so that both encode the same values)."""
    found = await double_variables(url)
    assert len(found) >= NODES, len(found)
    return found[:NODES]


def _start_s(*args: str) -> float:
    began = time.perf_counter()
    service = start_service(*args, timeout_s=180)
    elapsed = time.perf_counter() - began
    service.stop()
    return elapsed


def startup(runs: int = 3) -> None:
    """The service's start-up time: OPC UA off, cold, warm (medians of ``runs``)."""
    cache = tempfile.mkdtemp(prefix="opcua-bench-cache-")
    before = os.environ.get("CNC_OPCUA_CACHE_DIR")
    os.environ["CNC_OPCUA_CACHE_DIR"] = cache  # the services inherit it
    off, cold, warm = [], [], []
    try:
        for _ in range(runs):
            off.append(_start_s("--opcua", "off"))
            shutil.rmtree(cache, ignore_errors=True)
            cold.append(_start_s("--opcua", "opc.tcp://127.0.0.1:0"))
            warm.append(_start_s("--opcua", "opc.tcp://127.0.0.1:0"))
    finally:
        shutil.rmtree(cache, ignore_errors=True)
        if before is None:
            os.environ.pop("CNC_OPCUA_CACHE_DIR", None)
        else:
            os.environ["CNC_OPCUA_CACHE_DIR"] = before
    print(f"cnc-service start-up, {runs} runs (medians; target < 3 s):")
    for name, figures in (("OPC UA off", off), ("OPC UA, cold", cold), ("OPC UA, warm", warm)):
        print(f"  {name:22s} {statistics.median(figures):10.2f} s")


def main(runs: int = 3) -> None:
    reads(runs)
    startup(runs)
    from . import opcua_subscription_bench  # notifications and the cycle with sessions

    opcua_subscription_bench.main(runs)


def reads(runs: int = 3) -> None:
    """Read service figures against asyncua's static server."""
    ctx = mp.get_context("spawn")
    ready: mp.Queue = ctx.Queue()  # type: ignore[type-arg]
    static = ctx.Process(target=_serve_static, args=(ready,), daemon=True)
    static.start()
    port, static_ids = ready.get(timeout=120)
    service = start_service("--clock", "realtime", "--opcua", "opc.tcp://127.0.0.1:0",
                            timeout_s=180)
    try:
        url = next(line.split("OPC UA on ")[1].split()[0] for line in service.log
                   if "OPC UA on " in line)
        bound = asyncio.run(_bound_ids(url))
        ratios, base, ours = [], [], []
        for _ in range(runs):
            b = asyncio.run(_reads_per_s(f"opc.tcp://127.0.0.1:{port}", static_ids))
            o = asyncio.run(_reads_per_s(url, bound))
            base.append(b)
            ours.append(o)
            ratios.append(o / b)
        print(f"OPC UA Read, {NODES} nodes per call, {CALLS} calls, {runs} runs (medians):")
        print(f"  asyncua static server  {statistics.median(base):10.0f} reads/s")
        print(f"  cnc-service (bound)    {statistics.median(ours):10.0f} reads/s")
        print(f"  ratio                  {statistics.median(ratios):10.2f}  (target >= 0.8)")
    finally:
        service.stop()
        static.kill()


if __name__ == "__main__":
    runs = int(sys.argv[1]) if len(sys.argv) > 1 else 3
    {"reads": reads, "startup": startup}.get(
        sys.argv[2] if len(sys.argv) > 2 else "", main)(runs)
