"""cnc-web's machine pages in Chromium (headless, Playwright): continuous jog released on
key-up and on window blur, the program page opened while a program runs, the tool path
with axes, scale and the planned path without a click, workpiece coordinates under G54.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from cnc_objects.testing.web import WebProcess
from tests.support.browser import WAIT_MS, open_page

JOG_KEY = "ch1.ax1.manual_jog_plus_w"
# ten 6 mm moves at F600 (10 mm/s): 6 s of motion, line by line
LONG_PROGRAM = "".join(f"N{10 * k} G1 X{6 * k} F600\n" for k in range(1, 11)) + "N200 M30\n"
G54_PROGRAM = "N10 G54 G1 X20 Y10 F1200\nN20 G1 X0 Y0\nN30 M30\n"


async def _api(page: Any, method: str, path: str, body: Any = None) -> Any:
    """A request of the page's session (with its CSRF token); its status and JSON."""
    return await page.evaluate("""async ([method, path, body]) => {
        const s = await (await fetch('/api/session')).json();
        const r = await fetch(path, {method, headers: {'Content-Type': 'application/json',
            'X-CSRF-Token': s.csrf}, body: body === null ? undefined : JSON.stringify(body)});
        return [r.status, await r.json()];
    }""", [method, path, body])


async def _upload(page: Any, name: str, text: str) -> None:
    status = await page.evaluate("""async ([name, text]) => {
        const s = await (await fetch('/api/session')).json();
        const form = new FormData();
        form.append('file', new File([text], name));
        const r = await fetch('/api/programs', {method: 'POST', headers: {'X-CSRF-Token': s.csrf},
                                                body: form});
        return r.status;
    }""", [name, text])
    assert status == 200


async def _held(page: Any, held: bool) -> None:
    """Wait until the service's jog key of X+ is ``held`` (shown on the button)."""
    selector = f"#jog button[data-key='{JOG_KEY}']"
    await page.wait_for_function(
        "([s, held]) => document.querySelector(s).classList.contains('held') === held",
        arg=[selector, held], timeout=WAIT_MS)


async def test_continuous_jog_is_released_on_key_up_and_on_blur(page: Any,
                                                                web: WebProcess) -> None:
    await open_page(page, web.url, "mdi")
    await page.select_option("#jog-mode", "continuous")
    plus = page.locator(f"#jog button[data-key='{JOG_KEY}']")
    # held by the keyboard: moves while the key is down, stops at key-up
    await plus.focus()
    await page.keyboard.down("Space")
    await _held(page, True)
    await page.wait_for_function(
        "() => Number(document.querySelector('#jog tbody td[data-value]')?.textContent) > 0",
        timeout=WAIT_MS)
    await page.keyboard.up("Space")
    await _held(page, False)
    # held by the mouse: the window losing focus releases it, the button still pressed
    await plus.hover()
    await page.mouse.down()
    await _held(page, True)
    await page.evaluate("() => window.dispatchEvent(new Event('blur'))")
    await _held(page, False)
    await page.mouse.up()
    status, value = await _api(page, "GET", f"/api/read?name={JOG_KEY}")
    assert (status, value["value"]) == (200, False)


async def test_the_program_page_opened_while_a_program_runs_shows_it(
        page: Any, web: WebProcess) -> None:
    await open_page(page, web.url, "machine")
    await _upload(page, "long.nc", LONG_PROGRAM)
    status, _ = await _api(page, "POST", "/api/channel/1/select", {"program": "long.nc"})
    assert status == 200
    status, _ = await _api(page, "POST", "/api/channel/1/start", {})
    assert status == 200
    await page.wait_for_function(
        "() => /ACTIVE/.test(document.querySelector('#channels tbody tr')?.textContent ?? '')",
        timeout=WAIT_MS)
    await page.goto(f"{web.url}/#program")
    await page.wait_for_function(
        "() => document.querySelector('#program-name').textContent === 'long.nc'", timeout=WAIT_MS)
    assert await page.locator("#program-text li").count() == 11
    # the current line follows the channel: the one the block display names
    for _ in range(2):
        shown = await page.wait_for_function("""() => {
            const current = [...document.querySelectorAll('#program-text li')]
                .findIndex(li => li.classList.contains('current')) + 1;
            const block = document.querySelector('#program-block').textContent;
            return current > 1 && block.endsWith(`line ${current}`) ? current : false;
        }""", timeout=WAIT_MS)
        line = await shown.json_value()
        await page.wait_for_function(
            "n => document.querySelectorAll('#program-text li')[n - 1]?.classList.contains('current')"
            " === false",
            arg=line, timeout=WAIT_MS)
    # the path run so far is drawn while it runs
    await page.wait_for_function(
        "() => document.querySelector('#path-live').getAttribute('points').split(' ').length >= 5",
        timeout=WAIT_MS)


async def test_tool_path_has_axes_scale_and_the_planned_path_in_workpiece_coordinates(
        page: Any, web: WebProcess, tmp_path: Path) -> None:
    await open_page(page, web.url, "program")
    status, _ = await _api(page, "POST", "/api/channel/1/offsets/1",
                           {"offsets_mm": {"1": 10, "2": 5}})
    assert status == 200
    program = tmp_path / "g54.nc"
    program.write_text(G54_PROGRAM)
    await page.set_input_files("#upload-input", str(program))
    # the planned path is there without a click on "Draw path", with axes and a scale
    await page.wait_for_function(
        "() => document.querySelector('#path-planned').getAttribute('points').split(' ').length >= 10",
        timeout=WAIT_MS)
    assert await page.locator("#path-grid text").count() >= 6
    assert await page.locator("#path-grid text", has_text="X mm").count() == 1
    assert "grid" in str(await page.text_content("#path-scale"))
    await page.click("#start-program")
    await page.wait_for_function(
        "() => document.querySelector('#program-state').textContent === 'READY'", timeout=WAIT_MS)
    await page.wait_for_function(
        "() => /workpiece coordinates \\(G54\\)/.test(document.querySelector('#path-frame').textContent)",
        timeout=WAIT_MS)
    await page.wait_for_function(
        "() => document.querySelector('#position-line').textContent.split(/\\s+/).join(' ')"
        " === 'X 0.0000 Y 0.0000 mm'",
        timeout=WAIT_MS)
    # planned and run paths are drawn in one frame: the planned end is where the tool is
    end, tool = await page.evaluate("""() => [
        document.querySelector('#path-planned').getAttribute('points').split(' ').pop()
            .split(',').map(Number),
        ['cx', 'cy'].map(a => Number(document.querySelector('#path-tool').getAttribute(a)))]""")
    assert abs(end[0] - tool[0]) < 0.5 and abs(end[1] - tool[1]) < 0.5
    # the machine page shows both: machine X 10 (the offset), workpiece X 0
    await page.goto(f"{web.url}/#machine")
    await page.wait_for_function("""() => {
        const row = document.querySelector('#axes tbody tr');  // absent until the first frame
        const cells = row ? row.children : [];
        return cells.length > 2 && cells[1].textContent === '10.0000' && cells[2].textContent === '0.0000';
    }""", timeout=WAIT_MS)
