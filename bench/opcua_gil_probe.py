"""What holds the GIL while OPC UA sessions are subscribed (issue 40, the cycle's jitter).

    .venv/bin/python -m bench.opcua_gil_probe [OUT] [SECONDS]

The subscription bench's service (realtime clock, 1 ms cycle, a program running) with
``SESSIONS`` asyncua sessions of ``SESSION_ITEMS`` CncInterface Double variables at
``INTERVAL_MS``; while they are subscribed, ``py-spy record --gil`` samples the service
for ``SECONDS`` (a sample only where a thread holds the GIL) into ``OUT`` (py-spy's raw
format: one stack and its count a line), and the kernel's cycle figures over the same
time are printed. The summary gives the samples by thread and the frames most often in
them. Since OPC UA is served by a process of its own (docs/opcua.md), the service's GIL
holds only the hub's sampling and the link's frames; asyncua's work is in the child
(``py-spy record --pid`` of the pid the "OPC UA on" line names, to see it).
"""

from __future__ import annotations

import asyncio
import sys
from collections import Counter
from contextlib import AsyncExitStack
from pathlib import Path

from asyncua import Client

from .opcua_subscription_bench import (
    INTERVAL_MS,
    SESSION_ITEMS,
    SESSIONS,
    _Counter,
    _cycles,
    _double_variables,
    _opcua_bench_service,
    _start_program,
)

RATE_PER_S = 500


async def _sample(endpoint: str, url: str, pid: int, ids: list[str], out: Path,
                  seconds: float) -> None:
    async with AsyncExitStack() as stack:
        for _ in range(SESSIONS):
            client = await stack.enter_async_context(Client(url, timeout=60))
            sub = await client.create_subscription(INTERVAL_MS, _Counter())
            await sub.subscribe_data_change([client.get_node(i) for i in ids])
        await asyncio.sleep(1.5)  # every item has its first value; the flow is steady
        spy = await asyncio.create_subprocess_exec(
            str(Path(sys.executable).with_name("py-spy")), "record", "--gil", "--nonblocking",
            "-r", str(RATE_PER_S), "-d", str(int(seconds)), "-f", "raw", "-o", str(out),
            "-p", str(pid))
        print(await _cycles(endpoint, seconds))
        await spy.wait()


def summary(out: Path, top: int = 30) -> None:
    """Samples by thread (the stack's first frame) and the frames most often in them."""
    threads: Counter[str] = Counter()
    frames: Counter[str] = Counter()
    total = 0
    for line in out.read_text().splitlines():
        stack, count = line.rsplit(" ", 1)
        n = int(count)
        total += n
        names = [f.split(" (")[0] for f in stack.split(";")]
        threads[names[0]] += n
        for name in set(names):
            frames[name] += n
    print(f"{total} samples with the GIL held")
    for name, n in threads.most_common(5):
        print(f"  thread {name}: {n}")
    for name, n in frames.most_common(top):
        print(f"  {n:5d} {name}")


def main(out: Path, seconds: float) -> None:
    with _opcua_bench_service() as (service, url):
        asyncio.run(_start_program(service.endpoint))
        doubles = asyncio.run(_double_variables(url))
        ids = [doubles[k % len(doubles)] for k in range(SESSION_ITEMS)]
        asyncio.run(_sample(service.endpoint, url, service.process.pid, ids, out, seconds))
    summary(out)


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path("opcua_gil.txt"),
         float(sys.argv[2]) if len(sys.argv) > 2 else 8.0)
