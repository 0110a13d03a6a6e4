"""Virtual time: simulated seconds per wall second of the whole service (issue 22).

A service on the virtual clock (1 ms cycle, the default machine) runs, through the client
library as ``cnc run --wait`` does, the pocket example and a generated part of one hour of
machining; each with no subscription and with 20 on-change subscriptions to values that
move (held by a second connection). The figure is ``ch1.program_time`` divided by the
wall time from START to READY. Targets (issue 22): >= 500x with none, >= 100x with 20
subscriptions.

Short blocks (issue 37, ``short_blocks``): the look-ahead bench's spiral of 10 000 blocks
of 0.05 mm and a CAM finishing program of about 115 000 blocks
(``bench/programs/cam_finish.py``), the same way, in a table of their own. Targets:
>= 100x with none, >= 50x with 20 subscriptions.

Repeatable traces (issue 37, ``repeatable_traces``): the one-hour part on a service with
``--samples repeatable``, 20 cyclic subscriptions at 10 ms held by a second connection
that reads them as they come: the speed, and the samples delivered per wall second.

Before and after (issue 37, ``side_by_side``; ``python -m bench.virtual_bench --against
COMMIT``): a part on the service of an older commit and on this checkout's at once, the
runs alternating, so that a loaded machine's swings fall on both alike.

A 200 MB CAM program (issue 37, ``big_program_row``): the upload's MB/s, the service's
RSS while the program runs (read as a stream: flat, start / max) and the speed, over 60 s
of wall time (all of it would take hours at today's block rate), then RESET.
``web_rows`` (issue 37): the pocket and the one-hour part with cnc-web attached to the
service as ``make run`` starts it, and one browser-like session on its live WebSocket
watching what the machine page watches (app.js ``connectLive``: every channel's state
objects and every axis's positions, links, homing and jog keys, and the alarm counts; a
WebSocket client from aiohttp speaks the page's protocol, no browser runs). Target
>= 100x.
"""

from __future__ import annotations

import asyncio
import io
import statistics
import subprocess
import sys
import tarfile
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import aiohttp

from cnc_objects.clients import AsyncClient
from cnc_objects.testing.web import serving_web
from tests.support.cam_programs import write_cam_program
from tests.support.resources import rss_kib
from tests.support.service import start_service

from .jitter_bench import WATCHED
from .lookahead_programs import spiral
from .programs import cam_finish

ROOT = Path(__file__).resolve().parents[1]
SUBSCRIPTIONS = 20
#: Issue 37's targets (x real time) of the pocket and the one-hour part, by watching.
TARGETS = {0: 1000, SUBSCRIPTIONS: 200}


@dataclass(frozen=True)
class Row:
    """One row of the virtual part's table: a part, who watches it, its speed (simulated
    s per wall s, median of ``runs``) against ``target`` (None: a figure without one),
    and what else was measured (``note``)."""

    part: str
    watching: str
    machining_s: float
    speed: float
    target: float | None
    runs: int
    note: str = ""

    def line(self) -> str:
        """The row as the table prints it."""
        verdict = "" if self.target is None else (
            f">= {self.target:g}: {'met' if self.speed >= self.target else 'NOT met'}")
        runs = f"median of {self.runs}" if self.runs > 1 else "one run"
        note = f"; {self.note}" if self.note else ""
        return (f"{self.part:16} {self.watching:22} {self.machining_s:10.1f} "
                f"{self.speed:7.1f}x  {verdict:18} ({runs}{note})")


def print_table(rows: list[Row], realtime: tuple[str, ...] = ()) -> None:
    """Print issue 37's table: every row measured, then the realtime clock's rows (the
    jitter part's, when it ran in the same ``make bench``)."""
    print("\nvirtual time, whole service (1 ms cycle): simulated s per wall s, START to READY")
    print(f"{'part':16} {'watching':22} {'machining s':>10} {'speed':>8}  target")
    for row in rows:
        print(row.line())
    if realtime:
        print("\nrealtime clock (jitter part, same run)")
        print("\n".join(realtime))


def one_hour_part(blocks: int = 7200) -> str:
    """A zigzag of 5 mm blocks at F600 (0.5 s each): one hour of machining, and more for
    the corners' stops."""
    lines = ["N1 G90 G17 G1 F600"]
    for k in range(blocks):
        lines.append(f"X{(k % 2) * 5} Y{(k // 2) % 20 * 0.5:.1f}")
    return "\n".join(lines) + "\nM30\n"


def programs() -> dict[str, bytes]:
    """The three parts, by name."""
    return {
        "pocket-la-on.nc": (ROOT / "docs/examples/pocket-la-on.nc").read_bytes(),
        "one-hour.nc": one_hour_part().encode(),
    }


async def _run(endpoint: str, name: str, data: bytes, subscriptions: int) -> tuple[float, float]:
    """(simulated s, wall s) of one run of ``name``."""
    async with AsyncClient(endpoint, timeout_s=600) as c, AsyncClient(endpoint) as watcher:
        await c.upload(name, data)
        await c.wait_mdi(await c.mdi("G90 G0 X0 Y0 Z0"))  # every run from the origin
        tasks = []
        opened = asyncio.Event()
        sampled: set[str] = set()

        async def watch(obj: str) -> None:
            async for _ in watcher.subscribe(obj):
                sampled.add(obj)
                if len(sampled) >= subscriptions:
                    opened.set()

        for obj in WATCHED[:subscriptions]:
            tasks.append(asyncio.create_task(watch(obj)))
        if subscriptions:
            await opened.wait()  # every subscription has its first sample
        started = time.perf_counter()
        await c.run_program(name)
        await c.wait_program(timeout_s=3600)
        wall_s = time.perf_counter() - started
        simulated_s = await c.read("ch1.program_time")
        for task in tasks:
            task.cancel()
        await c.delete_program(name)
    return simulated_s, wall_s


BIG_PROGRAM_BYTES = 200_000_000  # a CAM finishing program as big as CAM writes them
BIG_WINDOW_S = 60.0  # wall time the big program runs before RESET (all of it takes hours)
_RSS_EVERY_S = 0.5


async def _run_big(endpoint: str, pid: int, path: Path) -> tuple[float, int, int, int, float]:
    """Upload ``path``, run it for ``BIG_WINDOW_S`` of wall time, RESET: (upload MB/s,
    RSS KiB before START, at the first sample, the most while running, speed)."""
    data = path.read_bytes()
    async with AsyncClient(endpoint, timeout_s=600) as c:
        started = time.perf_counter()
        await c.upload(path.name, data)
        upload_mb_s = len(data) / 1e6 / (time.perf_counter() - started)
        del data
        await c.wait_mdi(await c.mdi("G90 G0 X0 Y0 Z0"))
        before = rss_kib(pid)
        started = time.perf_counter()
        await c.run_program(path.name)
        samples = []
        while time.perf_counter() - started < BIG_WINDOW_S:
            samples.append(rss_kib(pid))
            await asyncio.sleep(_RSS_EVERY_S)  # a bench samples RSS over time
        simulated_s = await c.read("ch1.program_time")
        wall_s = time.perf_counter() - started
        await c.reset(1)
        await c.delete_program(path.name)
    return upload_mb_s, before, samples[0], max(samples), simulated_s / wall_s


def big_program_row() -> Row:
    """The row of a 200 MB CAM program, 0 subscriptions: upload MB/s, the service's RSS
    while it runs (read as a stream: flat) and the speed over ``BIG_WINDOW_S`` of wall
    time, after which it is RESET."""
    import tempfile

    with tempfile.TemporaryDirectory(prefix="cnc-bench-") as tmp:
        path = Path(tmp) / "cam-200mb.nc"
        write_cam_program(path, BIG_PROGRAM_BYTES)
        service = start_service("--clock", "virtual")
        try:
            upload, before, first, most, speed = asyncio.run(
                _run_big(service.endpoint, service.process.pid, path))
        finally:
            service.stop()
    return Row("cam-200mb.nc", "none", speed * BIG_WINDOW_S, speed, None, 1,
               f"upload {upload:.0f} MB/s; service RSS before START {before / 1024:.0f} MiB, "
               f"running {first / 1024:.0f} / max {most / 1024:.0f} MiB; "
               f"{BIG_WINDOW_S:.0f} s of wall time, then RESET")


def main(runs: int) -> list[Row]:
    """The pocket and the one-hour part with no and with 20 on-change subscriptions."""
    parts = programs()
    service = start_service("--clock", "virtual")
    rows = []
    try:
        for name, data in parts.items():
            for subscriptions in (0, SUBSCRIPTIONS):
                repeats = 1 if name == "one-hour.nc" else runs
                factors, sim = [], 0.0
                for _ in range(repeats):
                    sim, wall = asyncio.run(_run(service.endpoint, name, data, subscriptions))
                    factors.append(sim / wall)
                    print(f"virtual: {name} with {subscriptions} subscriptions: {sim:.1f} s "
                          f"in {wall:.2f} s ({sim / wall:.0f}x)", file=sys.stderr)
                watching = f"{subscriptions} on change" if subscriptions else "none"
                rows.append(Row(name, watching, sim, statistics.median(factors),
                                TARGETS[subscriptions], repeats))
    finally:
        service.stop()
    return rows


def all_rows(runs: int) -> list[Row]:
    """Every row of the virtual part (``make bench``), in the issue's order."""
    rows = main(runs)
    rows += web_rows(runs)
    rows += short_blocks(runs)
    rows.append(repeatable_traces(one_hour_part().encode()))
    rows.append(big_program_row())
    return rows


#: Cycle time of the repeatable-traces row's subscriptions.
TRACE_CYCLE_MS = 10


async def _run_traced(endpoint: str, name: str, data: bytes) -> tuple[float, float, int]:
    """(simulated s, wall s, samples delivered) of one run of ``name`` with
    ``SUBSCRIPTIONS`` cyclic subscriptions at ``TRACE_CYCLE_MS``: every due cycle's sample
    of each (repeatable samples), counted from START to READY."""
    async with AsyncClient(endpoint, timeout_s=3600) as c, AsyncClient(endpoint) as watcher:
        await c.upload(name, data)
        # the newest sequence number of each subscription: what the service delivered
        # (the client library's buffer of 1000 samples per subscription may drop some
        # when this task falls behind; the sequence numbers count them all the same)
        sequences: dict[str, int] = {}
        opened = asyncio.Event()

        async def watch(obj: str) -> None:
            async for sample in watcher.subscribe(obj, on_change=False,
                                                  cycle_ms=TRACE_CYCLE_MS):
                sequences[obj] = sample.sequence
                if len(sequences) >= SUBSCRIPTIONS:
                    opened.set()

        tasks = [asyncio.create_task(watch(obj)) for obj in WATCHED[:SUBSCRIPTIONS]]
        await opened.wait()  # every subscription has its first sample
        before = sum(sequences.values())
        started_s = time.perf_counter()
        await c.run_program(name)
        await c.wait_program(timeout_s=3600)
        wall_s = time.perf_counter() - started_s
        samples = sum(sequences.values()) - before
        simulated_s = await c.read("ch1.program_time")
        for task in tasks:
            task.cancel()
        await c.delete_program(name)
    return simulated_s, wall_s, samples


def repeatable_traces(data: bytes, runs: int = 1) -> Row:
    """The repeatable-traces row: the one-hour part with 20 subscriptions at 10 ms on a
    service with ``--samples repeatable`` (median of ``runs``)."""
    service = start_service("--clock", "virtual", "--samples", "repeatable")
    results = []
    try:
        for _ in range(runs):
            sim, wall, samples = asyncio.run(_run_traced(service.endpoint, "one-hour.nc", data))
            results.append((sim / wall, samples / wall, samples))
            print(f"virtual: one-hour.nc, repeatable samples, {SUBSCRIPTIONS} at "
                  f"{TRACE_CYCLE_MS} ms: {sim:.1f} s in {wall:.2f} s ({sim / wall:.0f}x), "
                  f"{samples} samples ({samples / wall:.0f}/s)", file=sys.stderr)
    finally:
        service.stop()
    factor = statistics.median(r[0] for r in results)
    rate = statistics.median(r[1] for r in results)
    delivered = statistics.median(r[2] for r in results)
    return Row("one-hour.nc", f"{SUBSCRIPTIONS} at {TRACE_CYCLE_MS} ms repeatable", sim, factor,
               None, runs, f"{rate:.0f} samples/s delivered, {delivered:.0f} in all, none lost")


# ------------------------------------------------------------------ with cnc-web (issue 37)

WEB_TARGET = 100  # x real time with cnc-web and one browser session
#: What app.js ``channelNames`` watches of a channel and of each of its axes.
PAGE_CHANNEL_LEAVES = (
    "mc_active_mode_r", "mc_active_state_r", "mc_active_program_name_r", "actual_block_number",
    "mc_active_file_name_r", "mc_active_line_r", "mc_active_feedrate_r",
    "mc_active_feed_override_r", "mc_active_single_block_r", "mc_error_count_r",
    "mc_spindle_mode_r", "mc_spindle_active_rev_r", "mc_spindle_override_w", "mc_active_tool_r",
    "mc_active_tool_offset_r", "mc_active_zero_offset_r")
PAGE_AXIS_LEAVES = ("command_position_acs", "command_position_pcs", "position_offset",
                    "link_state", "homing_referenced_r", "manual_jog_plus_w",
                    "manual_jog_minus_w")
PAGE_POSITION = "ch1.ax1.command_position_acs"  # moves in every part: the page is live


def page_names(machine: dict[str, Any]) -> list[str]:
    """The names the machine page watches when its live WebSocket opens (app.js
    ``connectLive``), for the machine cnc-web describes (``/api/machine``)."""
    names = []
    for ch in machine["channels"]:
        c = f"ch{ch['id']}"
        names += [f"{c}.{leaf}" for leaf in PAGE_CHANNEL_LEAVES]
        names.append(f"gpCh[{ch['plc_index']}].bahn_mc_control.suspend_axis_output.state_r")
        names += [f"{c}.ax{a['index']}.{leaf}" for a in ch["axes"] for leaf in PAGE_AXIS_LEAVES]
    return names + ["alarm_active_count_r", "alarm_raised_r"]


async def _run_watched_by_web(endpoint: str, url: str, name: str, data: bytes
                              ) -> tuple[float, float, int]:
    """(simulated s, wall s, position updates the session got) of one run of ``name``
    while one browser session of cnc-web at ``url`` watches the machine page."""
    jar = aiohttp.CookieJar(unsafe=True)  # the session cookie on 127.0.0.1
    async with aiohttp.ClientSession(cookie_jar=jar) as http, \
            AsyncClient(endpoint, timeout_s=600) as c:
        async with http.get(url + "/api/session"):
            pass
        async with http.get(url + "/api/machine") as response:
            names = page_names(await response.json())
        await c.upload(name, data)
        await c.wait_mdi(await c.mdi("G90 G0 X0 Y0 Z0"))  # every run from the origin
        updates = 0
        first = asyncio.Event()
        async with http.ws_connect(url + "/ws") as socket:
            await socket.send_json({"watch": names})

            async def receive() -> None:
                nonlocal updates
                async for message in socket:
                    if message.type != aiohttp.WSMsgType.TEXT:
                        continue
                    if PAGE_POSITION in message.json().get("values", {}):
                        updates += 1
                        first.set()

            receiver = asyncio.create_task(receive())
            await asyncio.wait_for(first.wait(), 30)  # the page shows its first values
            before = updates
            started = time.perf_counter()
            await c.run_program(name)
            await c.wait_program(timeout_s=3600)
            wall_s = time.perf_counter() - started
            receiver.cancel()
        simulated_s = await c.read("ch1.program_time")
        await c.delete_program(name)
    return simulated_s, wall_s, updates - before


def web_rows(runs: int) -> list[Row]:
    """The pocket and the one-hour part on the virtual clock with cnc-web attached and
    one browser session watching the machine page (target >= 100x)."""
    parts = programs()
    service = start_service("--clock", "virtual")
    rows = []
    try:
        with serving_web(service.endpoint) as web:
            for name in ("pocket-la-on.nc", "one-hour.nc"):
                repeats = 1 if name == "one-hour.nc" else runs
                factors, sim, updates = [], 0.0, 0
                for _ in range(repeats):
                    sim, wall, updates = asyncio.run(
                        _run_watched_by_web(service.endpoint, web.url, name, parts[name]))
                    factors.append(sim / wall)
                    print(f"virtual: {name} with cnc-web and one session: {sim:.1f} s in "
                          f"{wall:.2f} s ({sim / wall:.0f}x, {updates} position updates)",
                          file=sys.stderr)
                rows.append(Row(name, "cnc-web, one session", sim,
                                statistics.median(factors), WEB_TARGET, repeats))
    finally:
        service.stop()
    return rows


SHORT_BLOCK_TARGETS = {0: 100, SUBSCRIPTIONS: 50}  # issue 37: speed by subscriptions


def short_block_programs() -> dict[str, bytes]:
    """The short-block parts, by name: the spiral and the CAM finishing program
    (generated here: the generator is the source, see its docstring)."""
    return {
        "spiral.nc": spiral().text.encode(),
        "cam-finish.nc": cam_finish.program().encode("ascii"),
    }


def short_blocks(runs: int) -> list[Row]:
    """The short-block parts (issue 37), each with no and with 20 on-change
    subscriptions, medians of ``runs``."""
    parts = short_block_programs()
    service = start_service("--clock", "virtual")
    rows = []
    try:
        for name, data in parts.items():
            for subscriptions in (0, SUBSCRIPTIONS):
                factors, sim = [], 0.0
                for _ in range(runs):
                    sim, wall = asyncio.run(_run(service.endpoint, name, data, subscriptions))
                    factors.append(sim / wall)
                    print(f"virtual: {name} with {subscriptions} subscriptions: {sim:.1f} s "
                          f"in {wall:.2f} s ({sim / wall:.1f}x)", file=sys.stderr)
                watching = f"{subscriptions} on change" if subscriptions else "none"
                rows.append(Row(name, watching, sim, statistics.median(factors),
                                SHORT_BLOCK_TARGETS[subscriptions], runs,
                                f"{len(data)} bytes"))
    finally:
        service.stop()
    return rows


# ------------------------------------------------------- before and after, side by side

def export_tree(commit: str, into: Path) -> Path:
    """The repository at ``commit`` as a tree a service runs from (its working directory:
    ``python -m`` puts it first on the path): ``git archive``, the package's folders
    linked under ``cnc_objects`` as pyproject's ``package-dir`` maps them, and this
    checkout's compiled path (``build``; it loads only where the sources match)."""
    archive = subprocess.run(["git", "-C", str(ROOT), "archive", commit],
                             capture_output=True, check=True).stdout
    with tarfile.open(fileobj=io.BytesIO(archive)) as tar:
        tar.extractall(into, filter="data")
    for folder in ("service", "protocol", "objects", "clients"):
        (into / "cnc_objects" / folder).symlink_to(Path("..") / folder)
    if (ROOT / "build").exists():
        (into / "build").symlink_to(ROOT / "build")
    return into


def side_by_side(commit: str, runs: int, name: str = "pocket-la-on.nc",
                 subscriptions: tuple[int, ...] = (0, SUBSCRIPTIONS)) -> list[str]:
    """``name`` on two services at once, the one of ``commit`` and this checkout's, the
    runs alternating between them (``runs`` each per count of subscriptions): on a
    machine others load, one service's runs swing by 2x from minute to minute, and only
    runs taken turn about compare two versions (issue 37, docs/kernel.md "Watched at
    200x"). One line per count: the medians, and the service's CPU per run."""
    import tempfile

    data = (programs() | short_block_programs())[name]
    lines = []
    with tempfile.TemporaryDirectory(prefix="cnc-before-") as tmp:
        trees = {commit: export_tree(commit, Path(tmp)), "this checkout": None}
        services = {label: start_service("--clock", "virtual", cwd=tree)
                    for label, tree in trees.items()}
        try:
            for subs in subscriptions:
                speeds: dict[str, list[float]] = {label: [] for label in services}
                cpu_ms: dict[str, list[float]] = {label: [] for label in services}
                for k in range(runs):
                    turn = list(services.items())
                    for label, service in turn if k % 2 == 0 else reversed(turn):
                        before = _cpu_ms(service.process.pid)
                        sim, wall = asyncio.run(_run(service.endpoint, name, data, subs))
                        cpu_ms[label].append(_cpu_ms(service.process.pid) - before)
                        speeds[label].append(sim / wall)
                lines.append(f"{name}, {subs} on change: " + "; ".join(
                    f"{label} {statistics.median(speeds[label]):.0f}x (service CPU "
                    f"{statistics.median(cpu_ms[label]):.0f} ms a run)" for label in services)
                    + f"; medians of {runs}, alternating")
        finally:
            for service in services.values():
                service.stop()
    return lines


def _cpu_ms(pid: int) -> float:
    """CPU time of all threads of process ``pid`` so far (ms; Linux schedstat)."""
    total_ns = 0
    for task in Path(f"/proc/{pid}/task").iterdir():
        try:
            total_ns += int((task / "schedstat").read_text().split()[0])
        except OSError:  # a thread that ended meanwhile
            pass
    return total_ns / 1e6


if __name__ == "__main__":
    import argparse

    parser = argparse.ArgumentParser(
        description="A part on the service of an older commit and on this checkout's, "
                    "side by side (python -m bench.virtual_bench --against 56a115f)")
    parser.add_argument("--against", required=True, help="the commit to compare with")
    parser.add_argument("--runs", type=int, default=7)
    parser.add_argument("--part", default="pocket-la-on.nc")
    parser.add_argument("--subscriptions", default=f"0,{SUBSCRIPTIONS}")
    args = parser.parse_args()
    counts = tuple(int(n) for n in args.subscriptions.split(","))
    print("\n".join(side_by_side(args.against, args.runs, args.part, counts)))
