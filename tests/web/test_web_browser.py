"""cnc-web in a real browser: Debian's Chromium, headless, driven by Playwright.

Each page loads; a program uploaded by the file input runs from the page, its position
moves in the tool path and the state reaches READY; a refusal of the service is shown on
the message line in its words; a monitor finds every write control disabled, and a
write sent anyway is refused by the server.
"""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

from cnc_objects.clients.web.users import WebRole
from cnc_objects.testing.web import WebProcess
from tests.support.browser import WAIT_MS, open_page, page_message

from .conftest import PASSWORDS

PAGES = ("machine", "program", "mdi", "tools", "lookahead", "alarms", "objects")
# 30 mm at F1200 (20 mm/s): 1.5 s of motion, long enough to be seen moving.
MOVING_PROGRAM = "N10 G1 X30 Y10 F1200\nN20 G1 X0 Y0\nN30 M30\n"






async def test_each_page_loads(page: Any, web: WebProcess) -> None:
    for name in PAGES:
        await open_page(page, web.url, name)
        assert await page.is_visible(f"#page-{name}")
        for other in PAGES:
            if other != name:
                assert await page.is_hidden(f"#page-{other}")
        assert await page.get_attribute(f"#nav a[href='#{name}']", "class") == "active"
        await page.wait_for_function("() => window.cncStats.messages > 0", timeout=WAIT_MS)
    await open_page(page, web.url, "machine")
    await page.wait_for_function(
        "() => /DESELECTED/.test(document.querySelector('#channels tbody tr')?.textContent ?? '')",
        timeout=WAIT_MS)
    assert await page.locator("#axes tbody tr").count() == 6  # 2 channels x 3 axes
    await page.wait_for_function(
        "() => document.querySelector('#axes tbody tr td:nth-child(2)')?.textContent === '0.0000'",
        timeout=WAIT_MS)
    await open_page(page, web.url, "mdi")
    assert await page.locator("#jog tbody button.jog").count() == 6  # X Y Z, minus and plus


async def test_run_a_program_uploaded_by_the_file_input_and_drop(page: Any, web: WebProcess,
                                                        tmp_path: Path) -> None:
    program = tmp_path / "move.nc"
    program.write_text(MOVING_PROGRAM)
    await open_page(page, web.url, "program")
    await page.set_input_files("#upload-input", str(program))
    await page.wait_for_selector("#program-list li.selected[data-name='move.nc']", timeout=WAIT_MS)
    assert await page.locator("#program-text li").count() == 3
    await page_message(page, "uploaded move.nc")

    # a second program by drag and drop onto the drop box
    await page.evaluate("""() => {
        const data = new DataTransfer();
        data.items.add(new File(["N10 G1 X1 F600\\nN20 M30\\n"], "dropped.nc"));
        document.querySelector('#drop').dispatchEvent(
            new DragEvent('drop', {dataTransfer: data, bubbles: true, cancelable: true}));
    }""")
    await page.wait_for_selector("#program-list li.selected[data-name='dropped.nc']",
                                 timeout=WAIT_MS)
    assert await page.locator("#program-text li").count() == 2
    await page.click("#program-list li[data-name='move.nc']")
    await page.wait_for_function(
        "() => document.querySelector('#program-name').textContent === 'move.nc'", timeout=WAIT_MS)

    await page.click("#start-program")
    # the position moves: several distinct positions are drawn while the program runs
    await page.wait_for_function(
        "() => document.querySelector('#path-live').getAttribute('points').split(' ').length >= 5",
        timeout=WAIT_MS)
    await page.wait_for_selector("#program-text li.current", timeout=WAIT_MS)
    await page.wait_for_function(
        "() => document.querySelector('#program-state').textContent === 'READY'", timeout=WAIT_MS)
    assert re.fullmatch(r"X 0\.0000\s+Y 0\.0000 mm", str(await page.text_content("#position-line")))
    points = str(await page.get_attribute("#path-live", "points")).split(" ")
    assert len(set(points)) >= 5


async def test_positions_update_at_20_hz_while_a_program_runs(page: Any, web: WebProcess,
                                                              tmp_path: Path) -> None:
    program = tmp_path / "rate.nc"
    program.write_text("N10 G1 X100 F1200\nN20 M30\n")  # 5 s of motion
    await open_page(page, web.url, "program")
    await page.set_input_files("#upload-input", str(program))
    await page.wait_for_selector("#program-list li.selected[data-name='rate.nc']", timeout=WAIT_MS)
    await page.click("#start-program")
    await page.wait_for_function(
        "() => document.querySelector('#program-state').textContent === 'ACTIVE'", timeout=WAIT_MS)
    rate = await page.evaluate("""async () => {
        const before = window.cncStats.positionUpdates;
        const t0 = performance.now();
        await new Promise(r => setTimeout(r, 2000));
        return (window.cncStats.positionUpdates - before) * 1000 / (performance.now() - t0);
    }""")
    print(f"position updates in the browser: {rate:.1f} Hz")
    assert rate >= 20.0


async def test_a_refusal_is_shown_in_the_services_words(page: Any, web: WebProcess) -> None:
    await open_page(page, web.url, "objects")
    await page.fill("#object-pattern", "ch1.mc_command_feed_override_w")
    await page.click("#object-search button")
    await page.click("#object-table tbody tr button")
    row = page.locator("#watch-table tbody tr")
    await row.locator("input").fill("200")  # in %, the object's engineering unit
    await row.locator("button", has_text="Write").click()
    text = await page_message(page, "INVALIDDATA")
    assert text == "ADS 0x706 INVALIDDATA: feed override 200 % is outside 0..100 %"
    assert await page.get_attribute("#message", "class") == "error"
    # nothing was written
    value = await page.evaluate(
        "async () => (await (await fetch('/api/read?name=ch1.mc_active_feed_override_r')).json()).value")
    assert value == 1000


async def test_the_objects_page_shows_and_writes_engineering_units(page: Any,
                                                                   web: WebProcess) -> None:
    """Values in mm, %, rpm as the catalog's scale says (issue 36), the raw value in the
    cell's title; a write in % is the object's 0.1 %."""
    await open_page(page, web.url, "objects")
    await page.fill("#object-pattern", "ch1.mc_command_feed_override_w")
    await page.click("#object-search button")
    assert "%" in await page.locator("#object-table tbody tr td").nth(4).inner_text()
    await page.click("#object-table tbody tr button")
    await page.fill("#object-pattern", "ch1.mc_active_feed_override_r")
    await page.click("#object-search button")
    await page.click("#object-table tbody tr button")
    watched = page.locator("#watch-table tbody tr")
    await watched.nth(0).locator("input").fill("62.5")
    await watched.nth(0).locator("button", has_text="Write").click()
    cell = watched.nth(1).locator("td").nth(1)
    await page.wait_for_function(
        "() => document.querySelectorAll('#watch-table tbody tr')[1]"
        "?.querySelectorAll('td')[1]?.textContent === '62.5 %'", timeout=WAIT_MS)
    assert await cell.get_attribute("title") == "raw 625 0.1 %"
    value = await page.evaluate(
        "async () => (await (await fetch('/api/read?name=ch1.mc_active_feed_override_r')).json()).value")
    assert value == 625
    await watched.nth(0).locator("input").fill("100")
    await watched.nth(0).locator("button", has_text="Write").click()
    await page.wait_for_function(
        "() => document.querySelectorAll('#watch-table tbody tr')[1]"
        "?.querySelectorAll('td')[1]?.textContent === '100.0 %'", timeout=WAIT_MS)


async def test_a_monitor_finds_every_write_disabled_and_refused(page: Any,
                                                                signed_web: WebProcess) -> None:
    await page.goto(signed_web.url + "/")
    await page.wait_for_selector("#login:not([hidden])", timeout=WAIT_MS)
    await page.select_option("#login-role", "monitor")
    await page.fill("#login-password", PASSWORDS[WebRole.MONITOR])
    await page.click("#login-form button")
    await page.wait_for_selector("body[data-ready='1']", timeout=WAIT_MS)
    assert "monitor" in str(await page.text_content("#who"))
    for name in PAGES:
        await page.goto(f"{signed_web.url}/#{name}")
        await page.wait_for_selector(f"#page-{name}:not([hidden])", timeout=WAIT_MS)
        enabled = await page.evaluate(
            "() => [...document.querySelectorAll('.write')].filter(e => !e.disabled)"
            ".map(e => e.id || e.textContent)")
        assert enabled == [], f"write controls enabled for a monitor on {name}: {enabled}"
    assert await page.locator(".write").count() >= 15
    # send the write anyway, as a page's script would: the server refuses it
    answer = await page.evaluate("""async () => {
        const s = await (await fetch('/api/session')).json();
        const r = await fetch('/api/write', {method: 'POST', headers: {
            'Content-Type': 'application/json', 'X-CSRF-Token': s.csrf},
            body: JSON.stringify({name: 'ch1.mc_command_feed_override_w', value: 500})});
        return [r.status, await r.text()];
    }""")
    assert answer[0] == 403
    assert json.loads(answer[1])["error"] == (
        "ADS 0x704 INVALIDACCESS: role monitor may not write ch1.mc_command_feed_override_w; "
        "operator or admin may")
    # the page's own command path shows the same refusal on the message line
    await page.evaluate("() => document.querySelectorAll('[data-command]')"
                        ".forEach(b => b.disabled = false)")
    await page.goto(f"{signed_web.url}/#machine")
    await page.wait_for_selector("body[data-ready='1']", timeout=WAIT_MS)
    await page.evaluate("() => { const b = document.querySelector(\"[data-command='reset']\");"
                        " b.disabled = false; b.click(); }")
    text = await page_message(page, "INVALIDACCESS")
    assert text == "ADS 0x704 INVALIDACCESS: role monitor may not RESET channel 1; operator or admin may"
