"""cnc-web's live values and their cost to the service (``make bench``, part ``web``; issue 31).

A realtime service (1 ms cycle, the bench machine) runs a long program of 0.5 mm blocks.
Each run measures twice on the same service, ``seconds`` each, the cycle figures reset at
the start (``cnc_cycle_stats_reset_w``):

* without cnc-web;
* with cnc-web and ``SESSIONS`` WebSocket sessions, each watching what the machine page
  watches (every channel's state objects and every axis's positions, as app.js asks):
  the update rate of ``ch1.ax1.command_position_acs`` in each session, the subscriptions
  cnc-web holds at the service, and the same cycle figures.

The sessions speak the page's protocol over aiohttp's WebSocket client rather than ten
Chromium tabs: ten browsers would take the two cores the service needs and measure the
browsers. tests/web/test_web_browser.py measures the rate in Chromium itself.
Target (issue 31): >= 20 Hz in every session, cycle figures unchanged.
"""

from __future__ import annotations

import asyncio
import statistics
import sys
import time
from dataclasses import dataclass
from typing import Any

import aiohttp

from cnc_objects.clients import AsyncClient
from cnc_objects.testing.web import serving_web

from .jitter_bench import CycleFigures as Cycles
from .jitter_bench import program, realtime_bench_service

SESSIONS = 10
POSITION = "ch1.ax1.command_position_acs"
CHANNEL_LEAVES = ("mc_active_mode_r", "mc_active_state_r", "mc_active_program_name_r",
                  "actual_block_number", "mc_active_file_name_r", "mc_active_line_r",
                  "mc_active_feedrate_r", "mc_active_feed_override_r", "mc_active_single_block_r",
                  "mc_error_count_r", "mc_spindle_mode_r", "mc_spindle_active_rev_r",
                  "mc_spindle_override_w", "mc_active_tool_r", "mc_active_tool_offset_r",
                  "mc_active_zero_offset_r")
AXIS_LEAVES = ("command_position_acs", "command_position_pcs", "position_offset", "link_state")
CYCLE_FIGURES = ["cnc_tick_counter_r", "cnc_cycle_overruns_r", "cnc_cycle_jitter_p50_r",
                 "cnc_cycle_jitter_p99_r", "cnc_cycle_jitter_max_r", "cnc_cycle_exec_time_max_r"]


@dataclass(frozen=True)
class WebRun:
    """One run: cycles without and with cnc-web, and the sessions' position rates."""

    alone: Cycles
    with_web: Cycles
    rates_hz: list[float]
    subscriptions: int


def machine_page_names(machine: dict[str, Any]) -> list[str]:
    """The objects the machine page watches (app.js ``channelNames``)."""
    names = []
    for ch in machine["channels"]:
        c = f"ch{ch['id']}"
        names += [f"{c}.{leaf}" for leaf in CHANNEL_LEAVES]
        names.append(f"gpCh[{ch['plc_index']}].bahn_mc_control.suspend_axis_output.state_r")
        names += [f"{c}.ax{a['index']}.{leaf}" for a in ch["axes"] for leaf in AXIS_LEAVES]
    return names


async def _cycles(control: AsyncClient, seconds: float) -> Cycles:
    await control.write("cnc_cycle_stats_reset_w", True)
    before = await control.read("cnc_tick_counter_r")
    await asyncio.sleep(seconds)
    f = await control.read_many(CYCLE_FIGURES)
    return Cycles((f["cnc_tick_counter_r"] - before) & 0xFFFFFFFF, f["cnc_cycle_overruns_r"],
                  f["cnc_cycle_jitter_p50_r"], f["cnc_cycle_jitter_p99_r"],
                  f["cnc_cycle_jitter_max_r"], f["cnc_cycle_exec_time_max_r"])


async def _session(url: str, names: list[str], counts: list[int], k: int,
                   stop: asyncio.Event) -> None:
    async with aiohttp.ClientSession(cookie_jar=aiohttp.CookieJar(unsafe=True)) as http:
        async with http.get(url + "/api/session"):
            pass
        async with http.ws_connect(url + "/ws") as socket:
            await socket.send_json({"watch": names})
            while not stop.is_set():
                try:
                    message = await asyncio.wait_for(socket.receive_json(), 0.5)
                except TimeoutError:
                    continue
                if POSITION in message.get("values", {}):
                    counts[k] += 1


async def _with_web(endpoint: str, url: str, seconds: float, control: AsyncClient) -> WebRun:
    async with aiohttp.ClientSession(cookie_jar=aiohttp.CookieJar(unsafe=True)) as http:
        async with http.get(url + "/api/session"):
            pass
        async with http.get(url + "/api/machine") as response:
            names = machine_page_names(await response.json())
        counts = [0] * SESSIONS
        stop = asyncio.Event()
        sessions = [asyncio.create_task(_session(url, names, counts, k, stop))
                    for k in range(SESSIONS)]
        await asyncio.sleep(1.0)  # every session has its first values
        start_counts, started = list(counts), time.perf_counter()
        with_web = await _cycles(control, seconds)
        elapsed = time.perf_counter() - started
        rates = [(counts[k] - start_counts[k]) / elapsed for k in range(SESSIONS)]
        async with http.get(url + "/api/stats") as response:
            subscriptions = (await response.json())["subscriptions"]
        stop.set()
        await asyncio.gather(*sessions)
    return WebRun(Cycles(0, 0, 0, 0, 0, 0), with_web, rates, subscriptions)


def measure(runs: int, seconds: float) -> list[WebRun]:
    """``runs`` runs, each on a fresh realtime service: alone, then with cnc-web."""
    results = []
    for run in range(runs):
        with realtime_bench_service() as service:
            results.append(_one_run(service.endpoint, seconds))
        r = results[-1]
        print(f"web run {run + 1}/{runs}: p99 {r.alone.p99_us} -> {r.with_web.p99_us} us, "
              f"overruns {r.alone.overruns} -> {r.with_web.overruns}, position rate min "
              f"{min(r.rates_hz):.1f} Hz", file=sys.stderr)
    return results


def _one_run(endpoint: str, seconds: float) -> WebRun:
    async def alone() -> Cycles:
        async with AsyncClient(endpoint) as control:
            await control.upload("web.nc", program())
            await control.run_program("web.nc")
            await asyncio.sleep(1.0)  # the planner filled
            return await _cycles(control, seconds)

    quiet = asyncio.run(alone())
    with serving_web(endpoint) as web:
        async def loaded() -> WebRun:
            async with AsyncClient(endpoint) as control:
                return await _with_web(endpoint, web.url, seconds, control)

        run = asyncio.run(loaded())
    asyncio.run(_reset(endpoint))
    return WebRun(quiet, run.with_web, run.rates_hz, run.subscriptions)


async def _reset(endpoint: str) -> None:
    async with AsyncClient(endpoint) as control:
        await control.reset()


def main(runs: int, seconds: float) -> None:
    """Measure and print the table."""
    results = measure(runs, seconds)
    med = statistics.median
    low = med(min(r.rates_hz) for r in results)
    print(f"\ncnc-web: {SESSIONS} WebSocket sessions watching the machine page while a program "
          f"runs (realtime, 1 ms cycle); median of {runs} runs of {seconds:g} s")
    print(f"{'measurement':44} {'alone':>10} {'with web':>10}  target")
    print(f"{'position updates per session (min, Hz)':44} {'':>10} {low:10.1f}  >= 20: "
          f"{'met' if low >= 20 else 'NOT met'}")
    print(f"{'position updates per session (mean, Hz)':44} {'':>10} "
          f"{med(statistics.mean(r.rates_hz) for r in results):10.1f}")
    print(f"{'subscriptions cnc-web holds at the service':44} {'':>10} "
          f"{med(r.subscriptions for r in results):10.0f}")
    for label, key in (("cycles run per s", "cycles"), ("cycle lateness p50 (us)", "p50_us"),
                       ("cycle lateness p99 (us)", "p99_us"), ("cycle lateness max (us)", "max_us"),
                       ("longest cycle (execution, us)", "exec_max_us"), ("overruns", "overruns")):
        scale = seconds if key == "cycles" else 1.0
        a = med(getattr(r.alone, key) for r in results) / scale
        w = med(getattr(r.with_web, key) for r in results) / scale
        print(f"{label:44} {a:10.0f} {w:10.0f}")
