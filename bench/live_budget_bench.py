"""Issue 35's live-value and client figures, before and after the budgets:

    python -m bench.live_budget_bench

- unknown names: another session's slowest read while one WebSocket message names 200
  objects that do not exist;
- the same with 20 pages of 2 000 unknown names each;
- a greedy page: what a second session gets while one WebSocket watches 1 000 objects;
- churn: an operator's RESET through cnc-web (median, max) while 4 WebSockets watch and unwatch 2 000
  names over and over;
- cold catalogue: a fresh ``AsyncClient``'s ``gather`` of 500 reads (wall time, and the
  process's peak memory growth);
- bad input: the status of a jog with ``increment_mm`` NaN, and of ``limit=abc``.
"""

from __future__ import annotations

import asyncio
import resource
import statistics
import time
from typing import Any

import aiohttp

from cnc_objects.clients.client import AsyncClient
from cnc_objects.testing.process import start_service
from cnc_objects.testing.web import serving_web

CHURN_S = 5.0


def _session() -> aiohttp.ClientSession:
    return aiohttp.ClientSession(cookie_jar=aiohttp.CookieJar(unsafe=True))


async def _csrf(http: aiohttp.ClientSession, url: str) -> str:
    async with http.get(url + "/api/session") as response:
        return str((await response.json())["csrf"])


async def _slowest_read_s(http: aiohttp.ClientSession, url: str, until: asyncio.Event) -> float:
    slowest = 0.0
    while not until.is_set():
        started = time.perf_counter()
        async with http.get(url + "/api/read", params={"name": "cnc_tick_counter_r"}) as r:
            await r.read()
        slowest = max(slowest, time.perf_counter() - started)
        await asyncio.sleep(0.01)
    return slowest


async def unknown_names(url: str) -> None:
    async with _session() as monitor, _session() as other:
        await _csrf(monitor, url)
        await _csrf(other, url)
        done = asyncio.Event()
        reader = asyncio.create_task(_slowest_read_s(other, url, done))
        await asyncio.sleep(0.2)
        socket = await monitor.ws_connect(url + "/ws")
        started = time.perf_counter()
        await socket.send_json({"watch": [f"ch1.no_such_object_{k}" for k in range(200)]})
        errors: dict[str, Any] = {}
        while len(errors) < 200:
            errors.update((await socket.receive_json()).get("errors", {}))
        answered_s = time.perf_counter() - started
        done.set()
        slowest = await reader
        await socket.close()
    print(f"200 unknown names: all refused after {answered_s:.2f} s; another session's "
          f"slowest read meanwhile {slowest * 1000:.0f} ms")


async def many_pages(url: str) -> None:
    async with _session() as other:
        await _csrf(other, url)
        done = asyncio.Event()
        reader = asyncio.create_task(_slowest_read_s(other, url, done))

        async def page(k: int) -> None:
            async with _session() as http:
                await _csrf(http, url)
                async with http.ws_connect(url + "/ws") as socket:
                    names = [f"ch1.no_such_object_{k}_{i}" for i in range(2000)]
                    await socket.send_json({"watch": names})
                    errors: dict[str, Any] = {}
                    while len(errors) < len(names):
                        errors.update((await socket.receive_json()).get("errors", {}))

        started = time.perf_counter()
        await asyncio.gather(*(page(k) for k in range(20)))
        answered_s = time.perf_counter() - started
        done.set()
        slowest = await reader
    print(f"20 pages x 2000 unknown names: all refused after {answered_s:.2f} s; another "
          f"session's slowest read meanwhile {slowest * 1000:.0f} ms (its client shares "
          "this process's loop with the 20 pages)")


async def greedy_page(url: str, names: list[str]) -> None:
    async with _session() as greedy, _session() as other:
        await _csrf(greedy, url)
        await _csrf(other, url)
        socket = await greedy.ws_connect(url + "/ws")
        await socket.send_json({"watch": names[:1000]})  # the other's names are not among them
        got: dict[str, Any] = {}
        deadline = time.monotonic() + 20
        while time.monotonic() < deadline and len(got) < 1000:
            try:
                message = await asyncio.wait_for(socket.receive_json(), 2)
            except TimeoutError:
                break
            got.update(message.get("values", {}))
            got.update(message.get("errors", {}))
        second = await other.ws_connect(url + "/ws")
        wanted = names[-2:]
        await second.send_json({"watch": wanted})
        values: dict[str, Any] = {}
        errors: dict[str, Any] = {}
        while set(values) | set(errors) < set(wanted):
            message = await asyncio.wait_for(second.receive_json(), 20)
            values.update(message.get("values", {}))
            errors.update(message.get("errors", {}))
        await socket.close()
        await second.close()
    print(f"one page watching 1000 objects; another session gets values {sorted(values)}, "
          f"errors {errors}")


async def churn(url: str, names: list[str]) -> None:
    async def resets(n: int) -> list[float]:  # an operator's RESET on the web page
        times = []
        async with _session() as http:
            csrf = await _csrf(http, url)
            for _ in range(n):
                started = time.perf_counter()
                async with http.post(url + "/api/channel/1/reset",
                                     headers={"X-CSRF-Token": csrf}) as response:
                    assert response.status == 200, await response.text()
                times.append(time.perf_counter() - started)
                await asyncio.sleep(0.05)
        return times

    quiet = await resets(20)
    stop = asyncio.Event()

    async def churning(k: int) -> None:
        async with _session() as http:
            await _csrf(http, url)
            async with http.ws_connect(url + "/ws") as socket:
                chosen = names[k * 500:k * 500 + 2000] if len(names) > 2500 else names[:2000]
                while not stop.is_set():
                    await socket.send_json({"watch": chosen})
                    await asyncio.sleep(0.02)  # the subscriptions are on their way: let go
                    await socket.send_json({"unwatch": chosen})

    churners = [asyncio.create_task(churning(k)) for k in range(4)]
    await asyncio.sleep(1.0)
    started = time.monotonic()
    loaded: list[float] = []
    while time.monotonic() - started < CHURN_S:
        loaded += await resets(5)
    stop.set()
    await asyncio.gather(*churners, return_exceptions=True)
    print(f"RESET quiet: median {statistics.median(quiet) * 1000:.1f} ms, max "
          f"{max(quiet) * 1000:.1f} ms; during churn of 4 x 2000 names: median "
          f"{statistics.median(loaded) * 1000:.1f} ms, max {max(loaded) * 1000:.1f} ms")


async def cold_gather(endpoint: str, names: list[str]) -> None:
    before_kib = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    started = time.perf_counter()
    async with AsyncClient(endpoint, timeout_s=120) as c:
        try:
            await asyncio.wait_for(asyncio.gather(*(c.read(n) for n in names[:500])), 60)
            outcome = "done"
        except TimeoutError:
            outcome = "NOT done within 60 s"
    elapsed = time.perf_counter() - started
    grown_mib = (resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before_kib) / 1024
    print(f"cold gather of 500 reads: {outcome} in {elapsed:.2f} s, peak memory +{grown_mib:.0f} MiB")


async def bad_input(url: str) -> None:
    async with _session() as http:
        csrf = await _csrf(http, url)
        async with http.post(url + "/api/channel/1/jog", headers={"X-CSRF-Token": csrf},
                             json={"axis": 1, "direction": 1, "increment_mm": "nan"}) as r:
            jog = r.status
        async with http.get(url + "/api/read", params={"name": "ch1.mc_active_mode_r"}) as r:
            mode = (await r.json())["value"]
        async with http.get(url + "/api/objects", params={"limit": "abc"}) as r:
            limit = r.status
    print(f"jog increment_mm 'nan': {jog} (mode after: {mode}); /api/objects?limit=abc: {limit}")


async def main() -> None:
    service = start_service("--clock", "realtime")
    try:
        async with AsyncClient(service.endpoint) as c:
            names = [o.name for o in await c.browse("*") if "R" in o.access.upper()]
        await cold_gather(service.endpoint, names)
        with serving_web(service.endpoint) as web:
            await bad_input(web.url)
            await unknown_names(web.url)
            await many_pages(web.url)
            await greedy_page(web.url, names)
        with serving_web(service.endpoint) as web:
            await churn(web.url, names)
    finally:
        service.stop()


if __name__ == "__main__":
    asyncio.run(main())
