"""``make bench`` OPC UA part, subscriptions (issue 40): data-change notifications and
what OPC UA sessions cost the kernel's cycle.

Notifications: one asyncua client, one subscription of ``ITEMS`` monitored items at
``INTERVAL_MS``, counting the data changes it receives for ``seconds``:

- the baseline: asyncua's own server (second process) serving ``ITEMS`` static Double
  variables that a task of that server writes anew every ``INTERVAL_MS``;
- ``cnc-service`` (realtime clock, 1 ms cycle, the bench machine) running a long zigzag
  program (``jitter_bench.program``): ``ITEMS`` items over the Double variables of the
  CncInterface that change every sample while it runs (positions, distances to go),
  several items on each.

Each item can bring one notification per ``INTERVAL_MS`` on both: 10 000/s. The ratio is
taken within each run (baseline right before the service); target >= 0.8.

Jitter: the same service and program, the kernel's cycle figures over ``seconds``
(``cnc_cycle_stats_reset_w`` at the start) with no OPC UA session, then with
``SESSIONS`` sessions each subscribed to ``SESSION_ITEMS`` CncInterface variables at
``INTERVAL_MS`` (as web_bench compares the cycle without and with cnc-web). Target: no
cost beyond the run-to-run spread of the figures without sessions.

    python -m bench.opcua_subscription_bench [RUNS] [SECONDS]
"""

from __future__ import annotations

import asyncio
import multiprocessing as mp
import statistics
import sys
import tempfile
import time
from collections.abc import Iterator
from contextlib import AsyncExitStack, contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from asyncua import Client, Node, Server, ua

from cnc_objects.clients import AsyncClient
from cnc_objects.testing import ServiceProcess
from cnc_objects.testing.process import start_service

from .common import BENCH_MACHINE
from .jitter_bench import CycleFigures, program

ITEMS = 1000
INTERVAL_MS = 100.0
SESSIONS = 10
SESSION_ITEMS = 100
CNC_URI = "http://opcfoundation.org/UA/CNC"
CYCLE_FIGURES = ["cnc_tick_counter_r", "cnc_cycle_overruns_r", "cnc_cycle_jitter_p50_r",
                 "cnc_cycle_jitter_p99_r", "cnc_cycle_jitter_max_r", "cnc_cycle_exec_time_max_r"]
#: Samples a variable must bring in a second of the program to count as changing.
_CHANGING_PER_S = 8


class _Counter:
    """Counts the data changes of a subscription."""

    def __init__(self) -> None:
        self.count = 0
        self.per_node: dict[str, int] = {}

    def datachange_notification(self, node: Node, val: Any, data: Any) -> None:
        self.count += 1
        key = node.nodeid.to_string()
        self.per_node[key] = self.per_node.get(key, 0) + 1


def _serve_changing(ready: mp.Queue) -> None:  # type: ignore[type-arg]
    """asyncua's own server with ``ITEMS`` Double variables written anew every
    ``INTERVAL_MS`` (second process)."""

    async def main() -> None:
        server = Server()
        await server.init()
        server.set_endpoint("opc.tcp://127.0.0.1:0")
        server.set_security_policy([ua.SecurityPolicyType.NoSecurity])
        folder = await server.nodes.objects.add_folder(2, "Static")
        nodes = [await folder.add_variable(2, f"v{k}", 0.0) for k in range(ITEMS)]
        await server.start()
        ready.put((server.bserver.port, [n.nodeid.to_string() for n in nodes]))  # type: ignore[union-attr]
        step = 0
        period_s = INTERVAL_MS / 1000
        next_s = time.monotonic()
        while True:
            step += 1
            for k, node in enumerate(nodes):
                await server.write_attribute_value(
                    node.nodeid, ua.DataValue(ua.Variant(float(step * ITEMS + k), ua.VariantType.Double)))
            next_s += period_s
            await asyncio.sleep(max(0.0, next_s - time.monotonic()))

    asyncio.run(main())


async def _notifications_per_s(url: str, ids: list[str], seconds: float) -> float:
    """Data changes per second one subscription of ``len(ids)`` items receives."""
    async with Client(url, timeout=60) as client:
        counter = _Counter()
        sub = await client.create_subscription(INTERVAL_MS, counter)
        await sub.subscribe_data_change([client.get_node(i) for i in ids], queuesize=1)
        await asyncio.sleep(1.5)  # every item has its first value; the flow is steady
        before, began = counter.count, time.perf_counter()
        await asyncio.sleep(seconds)
        rate = (counter.count - before) / (time.perf_counter() - began)
        await sub.delete()
    return rate


async def double_variables(url: str) -> list[str]:
    """Every Double variable of the CncInterface's channels and axes."""
    async with Client(url, timeout=60) as client:
        ns = await client.get_namespace_index(CNC_URI)
        double = ua.NodeId(ua.ObjectIds.Double)
        found: list[str] = []
        for list_name in ("CncChannelList", "CncAxisList"):
            parent = await client.nodes.objects.get_child([f"{ns}:CncInterface",
                                                           f"{ns}:{list_name}"])
            for instance in await parent.get_children():
                for child in await instance.get_children(nodeclassmask=ua.NodeClass.Variable):
                    if child.nodeid.NamespaceIndex != ns:
                        continue
                    if await child.read_data_type() == double:
                        found.append(child.nodeid.to_string())
                    for c in await child.get_children(nodeclassmask=ua.NodeClass.Variable):
                        if c.nodeid.NamespaceIndex == ns and await c.read_data_type() == double:
                            found.append(c.nodeid.to_string())
        return found


async def _changing(url: str, ids: list[str]) -> list[str]:
    """Those of ``ids`` that bring a sample every ``INTERVAL_MS`` while the program runs."""
    async with Client(url, timeout=60) as client:
        counter = _Counter()
        sub = await client.create_subscription(INTERVAL_MS, counter)
        await sub.subscribe_data_change([client.get_node(i) for i in ids])
        await asyncio.sleep(1.0)
        counter.per_node.clear()
        await asyncio.sleep(1.0)
        await sub.delete()
    changing = [i for i in ids if counter.per_node.get(i, 0) >= _CHANGING_PER_S]
    assert changing, "no CncInterface variable changes while the program runs"
    return changing


@contextmanager
def _opcua_bench_service() -> Iterator[tuple[ServiceProcess, str]]:
    """A realtime service of the bench machine with OPC UA, and its OPC UA URL."""
    with tempfile.TemporaryDirectory() as tmp:
        machine = Path(tmp) / "bench.toml"
        machine.write_text(BENCH_MACHINE)
        service = start_service("--clock", "realtime", "--config", str(machine),
                                "--opcua", "opc.tcp://127.0.0.1:0", timeout_s=180)
        try:
            url = next(line.split("OPC UA on ")[1].split()[0] for line in service.log
                       if "OPC UA on " in line)
            yield service, url
        finally:
            service.stop()


async def _start_program(endpoint: str) -> None:
    async with AsyncClient(endpoint) as control:
        await control.upload("opcua.nc", program())
        await control.run_program("opcua.nc")
        await asyncio.sleep(1.0)  # the planner filled


async def _cycles(endpoint: str, seconds: float) -> CycleFigures:
    async with AsyncClient(endpoint) as control:
        await control.write("cnc_cycle_stats_reset_w", True)
        before = await control.read("cnc_tick_counter_r")
        await asyncio.sleep(seconds)
        f = await control.read_many(CYCLE_FIGURES)
    return CycleFigures((f["cnc_tick_counter_r"] - before) & 0xFFFFFFFF,
                        f["cnc_cycle_overruns_r"], f["cnc_cycle_jitter_p50_r"],
                        f["cnc_cycle_jitter_p99_r"], f["cnc_cycle_jitter_max_r"],
                        f["cnc_cycle_exec_time_max_r"])


async def _cycles_with_sessions(endpoint: str, url: str, ids: list[str], seconds: float
                                ) -> tuple[CycleFigures, float]:
    """The cycle figures while ``SESSIONS`` sessions are subscribed to ``ids``, and the
    notifications per second they receive together."""
    async with AsyncExitStack() as stack:
        counters = []
        for _ in range(SESSIONS):
            client = await stack.enter_async_context(Client(url, timeout=60))
            counter = _Counter()
            sub = await client.create_subscription(INTERVAL_MS, counter)
            await sub.subscribe_data_change([client.get_node(i) for i in ids])
            counters.append(counter)
        await asyncio.sleep(1.5)
        before, began = sum(c.count for c in counters), time.perf_counter()
        cycles = await _cycles(endpoint, seconds)
        rate = (sum(c.count for c in counters) - before) / (time.perf_counter() - began)
    return cycles, rate


@dataclass(frozen=True)
class SubscriptionRun:
    """One run: notifications against the baseline, the cycle without and with sessions."""

    baseline_per_s: float
    service_per_s: float
    alone: CycleFigures
    with_sessions: CycleFigures
    sessions_per_s: float


def _one_run(port: int, static_ids: list[str], seconds: float) -> SubscriptionRun:
    base = asyncio.run(_notifications_per_s(f"opc.tcp://127.0.0.1:{port}", static_ids, seconds))
    with _opcua_bench_service() as (service, url):
        asyncio.run(_start_program(service.endpoint))
        doubles = asyncio.run(double_variables(url))
        changing = asyncio.run(_changing(url, doubles))
        items = [changing[k % len(changing)] for k in range(ITEMS)]
        ours = asyncio.run(_notifications_per_s(url, items, seconds))
        alone = asyncio.run(_cycles(service.endpoint, seconds))
        session_ids = [doubles[k % len(doubles)] for k in range(SESSION_ITEMS)]
        loaded, sessions_rate = asyncio.run(
            _cycles_with_sessions(service.endpoint, url, session_ids, seconds))
    return SubscriptionRun(base, ours, alone, loaded, sessions_rate)


def measure(runs: int, seconds: float) -> list[SubscriptionRun]:
    """``runs`` runs; the baseline server lives through all of them."""
    ctx = mp.get_context("spawn")
    ready: mp.Queue = ctx.Queue()  # type: ignore[type-arg]
    static = ctx.Process(target=_serve_changing, args=(ready,), daemon=True)
    static.start()
    try:
        port, static_ids = ready.get(timeout=120)
        results = []
        for run in range(runs):
            results.append(_one_run(port, static_ids, seconds))
            r = results[-1]
            print(f"opcua subscriptions run {run + 1}/{runs}: {r.baseline_per_s:.0f} -> "
                  f"{r.service_per_s:.0f} notifications/s; cycle p99 {r.alone.p99_us} -> "
                  f"{r.with_sessions.p99_us} us", file=sys.stderr)
    finally:
        static.kill()
    return results


def main(runs: int = 3, seconds: float = 5.0) -> None:
    """Measure and print the figures (medians of ``runs``)."""
    results = measure(runs, seconds)
    med = statistics.median
    ratio = med(r.service_per_s / r.baseline_per_s for r in results)
    print(f"OPC UA data changes, {ITEMS} monitored items at {INTERVAL_MS:g} ms, {runs} runs "
          f"of {seconds:g} s (medians):")
    print(f"  asyncua server, values written every {INTERVAL_MS:g} ms "
          f"{med(r.baseline_per_s for r in results):10.0f} notifications/s")
    print(f"  cnc-service, program running           "
          f"{med(r.service_per_s for r in results):10.0f} notifications/s")
    print(f"  ratio                                  {ratio:10.2f}  (target >= 0.8: "
          f"{'met' if ratio >= 0.8 else 'NOT met'})")
    print(f"Kernel cycle with {SESSIONS} OPC UA sessions of {SESSION_ITEMS} items at "
          f"{INTERVAL_MS:g} ms (realtime, 1 ms cycle; medians, [spread without sessions]):")
    print(f"  {'':34} {'none':>10} {'sessions':>10}")
    print(f"  {'notifications/s to the sessions':34} {'':>10} "
          f"{med(r.sessions_per_s for r in results):10.0f}")
    for label, key in (("cycles run per s", "cycles"), ("cycle lateness p50 (us)", "p50_us"),
                       ("cycle lateness p99 (us)", "p99_us"), ("cycle lateness max (us)", "max_us"),
                       ("longest cycle (execution, us)", "exec_max_us"), ("overruns", "overruns")):
        scale = seconds if key == "cycles" else 1.0
        alone = [getattr(r.alone, key) / scale for r in results]
        loaded = [getattr(r.with_sessions, key) / scale for r in results]
        print(f"  {label:34} {med(alone):10.0f} {med(loaded):10.0f}  "
              f"[{min(alone):.0f}..{max(alone):.0f}]")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 3,
         float(sys.argv[2]) if len(sys.argv) > 2 else 5.0)
