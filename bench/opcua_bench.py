"""``make bench`` OPC UA part (issue 40).

Reads: asyncua's client reading 100 nodes per Read call, against asyncua's own server
serving 100 static variables (a second process: the baseline), then against the real
``cnc-service`` (realtime clock, 1 ms cycle) reading 100 bound CncInterface variables.
The ratio is taken within each run (baseline right before the service), its median
printed. Target: >= 0.8 of the baseline.

Notifications: 1 000 monitored items at 100 ms on 10 variables that change faster than
that (100 items each): on asyncua's server a task writes the 10 values every 10 ms; on
the service X and Y move (a 10 s program) and the items watch their positions and
distances to go. Data-change notifications received per second, ratio within each run.

Jitter: a realtime service of the bench machine runs a long program of short blocks; its
cycle figures (cnc_cycle_jitter_p50/p99/max, overruns) are taken alone, then with 10
OPC UA sessions each subscribed at 100 ms to every axis position and the channels' feeds
and states (as the web bench's 10 sessions watch the machine page).

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
    async with Client(url, timeout=30) as client:
        ns = await client.get_namespace_index(CNC_URI)
        found: list[str] = []
        for list_name in ("CncChannelList", "CncAxisList"):
            parent = await client.nodes.objects.get_child([f"{ns}:CncInterface",
                                                           f"{ns}:{list_name}"])
            for instance in await parent.get_children():
                for child in await instance.get_children(nodeclassmask=ua.NodeClass.Variable):
                    if child.nodeid.NamespaceIndex != ns:
                        continue
                    if await child.read_data_type() == ua.NodeId(ua.ObjectIds.Double):
                        found.append(child.nodeid.to_string())
                    else:  # a position: its ActPos, CmdPos, RemDist are Doubles
                        found += [c.nodeid.to_string() for c in await child.get_children(
                            nodeclassmask=ua.NodeClass.Variable)
                            if c.nodeid.NamespaceIndex == ns
                            and await c.read_data_type() == ua.NodeId(ua.ObjectIds.Double)]
        assert len(found) >= NODES, len(found)
        return found[:NODES]


ITEMS = 1000
WATCHED = 10
NOTIFY_S = 5.0  # seconds counted per measurement
MOVE = "G90 G1 X400 Y400 F2400\nM30\n"  # 10 s: X and Y move the whole time


def _serve_changing(ready: mp.Queue) -> None:  # type: ignore[type-arg]
    """asyncua's server with ``WATCHED`` Doubles rewritten every 10 ms (second process)."""

    async def main() -> None:
        server = Server()
        await server.init()
        server.set_endpoint("opc.tcp://127.0.0.1:0")
        server.set_security_policy([ua.SecurityPolicyType.NoSecurity])
        folder = await server.nodes.objects.add_folder(2, "Changing")
        nodes = [await folder.add_variable(2, f"v{k}", 0.0) for k in range(WATCHED)]
        await server.start()
        ready.put((server.bserver.port, [n.nodeid.to_string() for n in nodes]))  # type: ignore[union-attr]
        value = 0.0
        while True:
            value += 1.0
            for node in nodes:
                await server.write_attribute_value(node.nodeid, ua.DataValue(value))
            await asyncio.sleep(0.01)  # the baseline's own pace, not a synchronisation

    asyncio.run(main())


class _Count:
    def __init__(self) -> None:
        self.count = 0

    def datachange_notification(self, node: object, value: object, data: object) -> None:
        self.count += 1


async def _notifications_per_s(url: str, ids: list[str], started: asyncio.Event | None = None
                               ) -> float:
    async with Client(url, timeout=60) as client:
        counter = _Count()
        subscription = await client.create_subscription(100, counter)
        nodes = [client.get_node(ids[k % len(ids)]) for k in range(ITEMS)]
        await subscription.subscribe_data_change(nodes, queuesize=1)
        if started is not None:
            started.set()
        await asyncio.sleep(1.0)  # the first values out of the way (a measuring window)
        before, began = counter.count, time.perf_counter()
        await asyncio.sleep(NOTIFY_S)  # the measuring window
        rate = (counter.count - before) / (time.perf_counter() - began)
        await subscription.delete()
    return rate


async def _moving_ids(url: str) -> list[str]:
    """Positions and distances to go of X and Y: 10 Doubles that change while they move."""
    async with Client(url, timeout=30) as client:
        ns = await client.get_namespace_index(CNC_URI)
        found = []
        for axis in ("Ch1_X", "Ch1_Y"):
            for position in ("PosDirect", "PosIndirect"):
                for member in ("ActPos", "CmdPos") + (("RemDist",) if position == "PosDirect"
                                                      else ()):
                    node = await client.nodes.objects.get_child(
                        [f"{ns}:{n}" for n in ("CncInterface", "CncAxisList", axis, position,
                                               member)])
                    found.append(node.nodeid.to_string())
        return found[:WATCHED]


async def _service_notifications(url: str, endpoint: str, ids: list[str]) -> float:
    from cnc_objects.clients import AsyncClient

    async with AsyncClient(endpoint, timeout_s=60) as cnc:
        await cnc.reset(1)
        await cnc.upload("bench-move.nc", MOVE.encode())
        await cnc.upload("bench-back.nc", b"G90 G0 X0 Y0\nM30\n")
        started = asyncio.Event()
        counting = asyncio.create_task(_notifications_per_s(url, ids, started))
        await started.wait()
        await cnc.run_program("bench-move.nc", 1)
        rate = await counting
        await cnc.wait_program(1, 60)
        await cnc.run_program("bench-back.nc", 1)
        await cnc.wait_program(1, 60)
    return rate


def notifications(runs: int = 3) -> None:
    """Data-change notifications/s, 1 000 items at 100 ms, against asyncua's server."""
    ctx = mp.get_context("spawn")
    ready: mp.Queue = ctx.Queue()  # type: ignore[type-arg]
    changing = ctx.Process(target=_serve_changing, args=(ready,), daemon=True)
    changing.start()
    port, base_ids = ready.get(timeout=120)
    service = start_service("--clock", "realtime", "--opcua", "opc.tcp://127.0.0.1:0",
                            timeout_s=180)
    try:
        url = next(line.split("OPC UA on ")[1].split()[0] for line in service.log
                   if "OPC UA on " in line)
        ids = asyncio.run(_moving_ids(url))
        base, ours, ratios = [], [], []
        for _ in range(runs):
            b = asyncio.run(_notifications_per_s(f"opc.tcp://127.0.0.1:{port}", base_ids))
            o = asyncio.run(_service_notifications(url, service.endpoint, ids))
            base.append(b)
            ours.append(o)
            ratios.append(o / b)
        print(f"OPC UA data changes, {ITEMS} items at 100 ms on {WATCHED} variables, "
              f"{runs} runs (medians):")
        print(f"  asyncua server (10 ms writes) {statistics.median(base):8.0f} notifications/s")
        print(f"  cnc-service (X, Y moving)     {statistics.median(ours):8.0f} notifications/s")
        print(f"  ratio                         {statistics.median(ratios):8.2f}  (target >= 0.8)")
    finally:
        service.stop()
        changing.kill()


SESSIONS = 10
JITTER_S = 10.0


async def _session_items(url: str) -> list[str]:
    """What a dashboard watches: every position member of every axis, the channels'
    feeds, overrides and states."""
    async with Client(url, timeout=30) as client:
        ns = await client.get_namespace_index(CNC_URI)
        interface = await client.nodes.objects.get_child(f"{ns}:CncInterface")
        found = []
        axes = await (await interface.get_child(f"{ns}:CncAxisList")).get_children()
        for axis in axes:
            for position in ("PosDirect", "PosIndirect"):
                node = await axis.get_child(f"{ns}:{position}")
                found += [c.nodeid.to_string() for c in await node.get_children()
                          if c.nodeid.NamespaceIndex == ns]
        channels = await (await interface.get_child(f"{ns}:CncChannelList")).get_children()
        for channel in channels:
            for name in ("ActFeedrate", "CmdFeedrate", "ActOverride", "ActStatus",
                         "ActProgramStatus", "ActProgramName", "ActProgramBlock"):
                found.append((await channel.get_child(f"{ns}:{name}")).nodeid.to_string())
        return found


async def _with_sessions(url: str, endpoint: str, ids: list[str]) -> object:
    from cnc_objects.clients import AsyncClient

    from .web_bench import _cycles

    async with AsyncClient(endpoint) as control:
        clients = [Client(url, timeout=60) for _ in range(SESSIONS)]
        for client in clients:
            await client.connect()
            subscription = await client.create_subscription(100, _Count())
            await subscription.subscribe_data_change([client.get_node(i) for i in ids])
        await asyncio.sleep(1.0)  # every session has its first values (a settling time)
        figures = await _cycles(control, JITTER_S)
        for client in clients:
            await client.disconnect()
    return figures


def jitter(runs: int = 3) -> None:
    """Cycle figures alone and with 10 OPC UA sessions subscribed (realtime clock)."""
    from cnc_objects.clients import AsyncClient

    from .common import BENCH_MACHINE
    from .jitter_bench import program
    from .web_bench import _cycles

    async def alone(endpoint: str) -> object:
        async with AsyncClient(endpoint) as control:
            await control.upload("opcua-jitter.nc", program())
            await control.run_program("opcua-jitter.nc")
            await asyncio.sleep(1.0)  # the planner filled (a settling time)
            return await _cycles(control, JITTER_S)

    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        machine = f"{tmp}/bench.toml"
        with open(machine, "w") as out:
            out.write(BENCH_MACHINE)
        for _ in range(runs):
            service = start_service("--clock", "realtime", "--config", machine,
                                    "--opcua", "opc.tcp://127.0.0.1:0", timeout_s=180)
            try:
                url = next(line.split("OPC UA on ")[1].split()[0] for line in service.log
                           if "OPC UA on " in line)
                ids = asyncio.run(_session_items(url))
                quiet = asyncio.run(alone(service.endpoint))
                loaded = asyncio.run(_with_sessions(url, service.endpoint, ids))
                rows.append((quiet, loaded, len(ids)))
            finally:
                service.stop()
    med = statistics.median
    print(f"cycle figures, realtime 1 ms, {JITTER_S:g} s each, {runs} runs (medians): alone "
          f"-> with {SESSIONS} OPC UA sessions of {rows[0][2]} items at 100 ms")
    for field in ("p50_us", "p99_us", "max_us", "overruns"):
        before = med(getattr(r[0], field) for r in rows)
        after = med(getattr(r[1], field) for r in rows)
        print(f"  {field:10s} {before:8g} -> {after:8g}")


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
    notifications(runs)
    jitter(runs)
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
    {"reads": reads, "notifications": notifications, "startup": startup,
     "jitter": jitter}.get(
        sys.argv[2] if len(sys.argv) > 2 else "", main)(runs)
