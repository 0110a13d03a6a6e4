"""What cnc-web's page costs the browser while a program runs (issue 38).

``python -m bench.web_cpu_bench [--runs 3] [--seconds 10] [--page machine]``

A realtime service of the bench machine runs a long program of 0.5 mm blocks (20 mm/s,
positions change every cycle); cnc-web serves the page from this checkout's
``clients/web/static``. Each run opens a fresh Chromium page (Debian's, headless, as the
browser tests start it) on ``--page``, waits until the channel shows ACTIVE, then reads
Chromium's own counters over CDP (``Performance.getMetrics``) at the start and the end of
``--seconds``: ``TaskDuration`` (all the renderer main thread's work: script, style,
layout, paint), ``ScriptDuration`` (JavaScript only) and ``LayoutDuration`` +
``RecalcStyleDuration``, as a share of the wall time. The median of ``--runs`` runs is
printed.

To compare two versions of the page, run it on each in the same hour on the same
machine (docs/web.md "Per-page modules" shows how: the old static files checked out
with ``git checkout <commit> -- clients/web/static``).
"""

from __future__ import annotations

import argparse
import asyncio
import json
import shutil
import statistics
import sys
import time
import urllib.request
from dataclasses import dataclass
from http.cookiejar import CookieJar
from typing import Any

from cnc_objects.testing.web import serving_web

from .jitter_bench import program, realtime_bench_service

CHROMIUM_PATHS = ("/usr/bin/chromium", "/usr/bin/chromium-browser")
PROGRAM = "webcpu.nc"
METRICS = ("TaskDuration", "ScriptDuration", "LayoutDuration", "RecalcStyleDuration")
WAIT_S = 30.0
# the session cookie of the bench's own API calls (cnc-web keeps sessions by cookie)
OPENER = urllib.request.build_opener(urllib.request.HTTPCookieProcessor(CookieJar()))


@dataclass(frozen=True)
class PageCost:
    """One run: the share of wall time (%) the page's main thread spent, by counter."""

    task_pct: float
    script_pct: float
    layout_style_pct: float
    frames: int


def _post(url: str, body: dict[str, Any], csrf: str) -> None:
    request = urllib.request.Request(url, data=json.dumps(body).encode(), method="POST",
                                     headers={"Content-Type": "application/json",
                                              "X-CSRF-Token": csrf})
    with OPENER.open(request, timeout=WAIT_S) as reply:
        reply.read()


def _start_program(web_url: str) -> None:
    """Upload the long program (first time) and start it in channel 1 through cnc-web."""
    with OPENER.open(web_url + "/api/session", timeout=WAIT_S) as reply:
        csrf = json.loads(reply.read())["csrf"]
    _post(f"{web_url}/api/channel/1/reset", {}, csrf)
    _post(f"{web_url}/api/channel/1/select", {"program": PROGRAM}, csrf)
    _post(f"{web_url}/api/channel/1/start", {}, csrf)


def _upload(web_url: str) -> None:
    with OPENER.open(web_url + "/api/session", timeout=WAIT_S) as reply:
        csrf = json.loads(reply.read())["csrf"]
    boundary = "webcpubench"
    body = (f"--{boundary}\r\nContent-Disposition: form-data; name=\"file\"; "
            f"filename=\"{PROGRAM}\"\r\n\r\n").encode() + program(4_000) + \
        f"\r\n--{boundary}--\r\n".encode()
    request = urllib.request.Request(
        web_url + "/api/programs", data=body, method="POST",
        headers={"Content-Type": f"multipart/form-data; boundary={boundary}", "X-CSRF-Token": csrf})
    with OPENER.open(request, timeout=WAIT_S) as reply:
        reply.read()


async def _metrics(session: Any) -> dict[str, float]:
    answer = await session.send("Performance.getMetrics")
    return {m["name"]: float(m["value"]) for m in answer["metrics"]}


async def measure_once(browser: Any, web_url: str, page_name: str, seconds: float) -> PageCost:
    """One fresh page on ``page_name`` while the program runs: its main thread's cost."""
    await asyncio.to_thread(_start_program, web_url)
    context = await browser.new_context(viewport={"width": 1366, "height": 768})
    try:
        page = await context.new_page()
        await page.goto(f"{web_url}/#machine")
        await page.wait_for_selector("body[data-ready='1']", timeout=WAIT_S * 1000)
        await page.wait_for_function(
            "() => /ACTIVE/.test(document.querySelector('#channels tbody tr')?.textContent ?? '')",
            timeout=WAIT_S * 1000)
        if page_name != "machine":
            await page.goto(f"{web_url}/#{page_name}")
        session = await context.new_cdp_session(page)
        await session.send("Performance.enable", {"timeDomain": "threadTicks"})
        await page.evaluate("""() => { window.benchFrames = 0;
            const count = () => { window.benchFrames += 1; requestAnimationFrame(count); };
            requestAnimationFrame(count); }""")
        before = await _metrics(session)
        started = time.perf_counter()
        await asyncio.sleep(seconds)  # the measured window itself, not a synchronisation
        after = await _metrics(session)
        wall_s = time.perf_counter() - started
        frames = int(await page.evaluate("() => window.benchFrames"))
        share = {name: (after[name] - before[name]) / wall_s * 100 for name in METRICS}
        return PageCost(share["TaskDuration"], share["ScriptDuration"],
                        share["LayoutDuration"] + share["RecalcStyleDuration"], frames)
    finally:
        await context.close()


async def measure(runs: int, seconds: float, page_name: str) -> list[PageCost]:
    """``runs`` fresh pages on one service and cnc-web."""
    from playwright.async_api import async_playwright

    chromium = next((p for p in CHROMIUM_PATHS if shutil.which(p)), None)
    if chromium is None:
        raise SystemExit("Debian's chromium is not installed (apt-get install chromium)")
    with realtime_bench_service() as service, serving_web(service.endpoint) as web:
        await asyncio.to_thread(_upload, web.url)
        async with async_playwright() as driver:
            browser = await driver.chromium.launch(executable_path=chromium,
                                                   args=["--no-sandbox", "--disable-gpu"])
            try:
                return [await measure_once(browser, web.url, page_name, seconds)
                        for _ in range(runs)]
            finally:
                await browser.close()


def main(argv: list[str] | None = None) -> int:
    """Measure and print the runs and their medians."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--seconds", type=float, default=10.0)
    parser.add_argument("--page", default="machine")
    args = parser.parse_args(argv)
    costs = asyncio.run(measure(args.runs, args.seconds, args.page))
    for k, cost in enumerate(costs, 1):
        print(f"run {k}: main thread {cost.task_pct:5.1f} %, script {cost.script_pct:5.1f} %, "
              f"layout+style {cost.layout_style_pct:5.1f} %, {cost.frames} frames")
    median = {field: statistics.median(getattr(c, field) for c in costs)
              for field in ("task_pct", "script_pct", "layout_style_pct")}
    print(f"median of {len(costs)} x {args.seconds:g} s on #{args.page}: main thread "
          f"{median['task_pct']:.1f} %, script {median['script_pct']:.1f} %, "
          f"layout+style {median['layout_style_pct']:.1f} % of one core")
    return 0


if __name__ == "__main__":
    sys.exit(main())
