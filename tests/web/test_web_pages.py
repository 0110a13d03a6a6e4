"""cnc-web's browser side as per-page ES modules (issue 38).

Every module the page imports is served as JavaScript (a browser refuses a module of
another type); the facts the pages show (the 0.1 um scale, the value names, the
engineering units) come from ``GET /api/facts``, built from the Python constants, and
are not typed again in the JavaScript; a frame draws the visible page only.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

from cnc_objects.clients.channel_ops import CONTOUR_BLOCK_TYPES
from cnc_objects.clients.web.server import STATIC_DIR
from cnc_objects.objects.catalog import Scope, templates
from cnc_objects.objects.units import scale_of
from cnc_objects.protocol.units import UM01_PER_MM
from cnc_objects.protocol.values import (
    WORKING_STATES,
    ChannelMode,
    ChannelState,
    LinkState,
    SpindleMode,
)
from cnc_objects.testing.web import WebProcess
from tests.support.browser import WAIT_MS, open_page
from tests.support.web_http import browser_session, json_request

JAVASCRIPT_TYPES = ("text/javascript", "application/javascript")
MODULE_SCRIPT = re.compile(r'<script type="module" src="([^"]+)"></script>')
IMPORT = re.compile(r'^import (?:[^"]*? from )?"(\./[\w.]+\.js)";', re.MULTILINE)
# facts the JavaScript once typed itself: each must come from /api/facts now
RETYPED = {
    "the 0.1 um scale": re.compile(r"\b10_?000\b|UM01_PER_MM"),
    "a spindle mode table": re.compile(r'\{\s*1:\s*"M5"'),
    "a link state table": re.compile(r'"waiting ack"'),
    "a look-ahead block type table": re.compile(r'"polynomial"|"LOG PARAM"'),
    "the working states": re.compile(r'\[\s*"ACTIVE",\s*"HOLD"\s*\]'),
    "the feed in mm/min": re.compile(r"\*\s*60\s*/\s*1000"),
    "the spindle speed in rpm": re.compile(r"/\s*6000\b"),
    "an override in %": re.compile(r"(/|\*)\s*10\b(?!\d)"),
}


async def test_every_module_the_page_imports_is_served_as_javascript(web: WebProcess) -> None:
    async with browser_session() as http:
        async with http.get(web.url + "/") as reply:
            entries = MODULE_SCRIPT.findall(await reply.text())
        assert entries == ["/static/main.js"]
        seen: dict[str, str] = {}
        todo = list(entries)
        while todo:
            path = todo.pop()
            if path in seen:
                continue
            async with http.get(web.url + path) as reply:
                assert reply.status == 200, path
                seen[path] = reply.content_type
                todo += ["/static/" + name[2:] for name in IMPORT.findall(await reply.text())]
    assert {path: kind for path, kind in seen.items() if kind not in JAVASCRIPT_TYPES} == {}
    # the core and one module per page, all reached from main.js
    pages = {"machine", "program", "mdi", "tools", "lookahead", "alarms", "objects"}
    assert {f"/static/{name}.js" for name in pages | {"core", "live", "router"}} <= set(seen)
    assert set(seen) == {f"/static/{p.name}" for p in STATIC_DIR.glob("*.js")}


async def test_the_facts_are_the_python_constants(web: WebProcess) -> None:
    async with browser_session() as http:
        await json_request(http, "GET", web.url + "/api/session")  # the session's cookie
        status, facts = await json_request(http, "GET", web.url + "/api/facts")
    assert status == 200
    assert facts["um01_per_mm"] == UM01_PER_MM
    assert facts["modes"] == {str(int(m)): m.name for m in ChannelMode}
    assert facts["states"] == {str(int(s)): s.name for s in ChannelState}
    assert set(facts["working_states"]) == {s.name for s in WORKING_STATES}
    assert facts["contour_types"] == {str(k): v for k, v in CONTOUR_BLOCK_TYPES.items()}
    assert facts["link_states"] == {"0": "linked", "1": "requested", "2": "waiting ack"}
    assert set(facts["link_states"]) == {str(int(s)) for s in LinkState}
    assert {k: facts["spindle_modes"][str(int(k))] for k in (SpindleMode.M05, SpindleMode.M03,
            SpindleMode.M04, SpindleMode.M19)} == {SpindleMode.M05: "M5", SpindleMode.M03: "M3",
                                                   SpindleMode.M04: "M4", SpindleMode.M19: "M19"}
    channel_units = {t.element: t.unit for t in templates()
                     if t.scope in (Scope.CHANNEL, Scope.CHANNEL_AXIS) and scale_of(t.unit)}
    assert set(channel_units) <= set(facts["scales"])
    for leaf, unit in channel_units.items():
        scale = scale_of(unit)
        assert scale is not None
        assert facts["scales"][leaf] == {"unit": scale.unit, "factor": scale.factor,
                                         "decimals": scale.decimals}, leaf
    # what the machine page shows: mm/min, %, rpm, mm
    shown = {leaf: facts["scales"][leaf]["unit"] for leaf in (
        "mc_active_feedrate_r", "mc_active_feed_override_r", "mc_spindle_active_rev_r",
        "command_position_acs", "command_position_pcs")}
    assert shown == {"mc_active_feedrate_r": "mm/min", "mc_active_feed_override_r": "%",
                     "mc_spindle_active_rev_r": "rpm", "command_position_acs": "mm",
                     "command_position_pcs": "mm"}


def test_the_javascript_types_no_fact_of_the_service() -> None:
    found = []
    for script in sorted(Path(STATIC_DIR).glob("*.js")):
        for number, line in enumerate(script.read_text(encoding="utf-8").splitlines(), 1):
            code = line.split("//")[0] if not line.lstrip().startswith("//") else ""
            found += [f"{script.name}:{number}: {what}: {line.strip()}"
                      for what, pattern in RETYPED.items() if pattern.search(code)]
    assert found == []


async def _rendered(page: Any) -> dict[str, int]:
    return dict(await page.evaluate("() => ({...window.cncStats.rendered})"))


async def test_a_frame_draws_the_visible_page_only(page: Any, web: WebProcess) -> None:
    """While positions stream in, the machine page draws and the hidden pages do not; a
    page shown draws at once, and the page it replaced stops drawing."""
    await open_page(page, web.url, "machine")
    status = await page.evaluate("""async () => {
        const s = await (await fetch('/api/session')).json();
        const post = (path, body) => fetch(path, {method: 'POST', headers: {
            'Content-Type': 'application/json', 'X-CSRF-Token': s.csrf}, body: JSON.stringify(body)});
        return (await post('/api/channel/1/mdi', {blocks: 'G91 G1 X200 F1200'})).status;
    }""")
    assert status == 200
    await page.wait_for_function("() => (window.cncStats.rendered.machine ?? 0) > 20 && "
                                 "window.cncStats.positionUpdates > 20", timeout=WAIT_MS)
    assert set(await _rendered(page)) == {"machine"}
    await page.evaluate("() => { location.hash = 'mdi'; }")
    await page.wait_for_function("() => window.cncStats.rendered.mdi >= 1", timeout=WAIT_MS)
    machine = (await _rendered(page))["machine"]
    await page.wait_for_function("""() => { window.updatesThen ??= window.cncStats.positionUpdates;
        return window.cncStats.positionUpdates > window.updatesThen + 20; }""", timeout=WAIT_MS)
    after = await _rendered(page)
    assert after["mdi"] > 1
    # the frame that showed the mdi page may have been queued while machine was visible
    assert after["machine"] <= machine + 1
    assert set(after) == {"machine", "mdi"}
