"""A program as big as CAM writes it, on cnc-web's page in Chromium: uploaded in slices
with a progress bar (and cancelled), shown a window of lines at a time."""

from __future__ import annotations

import asyncio
from pathlib import Path
from typing import Any

from cnc_objects.testing import ServiceProcess
from cnc_objects.testing.web import WebProcess
from tests.support.browser import WAIT_MS, open_page, page_message
from tests.support.uploads import g1_program, leftovers

WATCH_PROGRESS = """() => {
    window.progressSeen = [];
    new MutationObserver(() => window.progressSeen.push(
        document.querySelector('#upload-progress').value))
        .observe(document.querySelector('#upload-status'),
                 {childList: true, characterData: true, subtree: true});
}"""


async def test_a_big_program_uploads_with_progress_and_shows_a_window(
        page: Any, web: WebProcess, realtime_service: ServiceProcess, tmp_path: Path) -> None:
    program = g1_program(12_000_000)  # three slices
    lines = program.decode().splitlines()
    local = tmp_path / "cam.nc"
    local.write_bytes(program)
    await open_page(page, web.url, "program")
    await page.evaluate(WATCH_PROGRESS)
    await page.set_input_files("#upload-input", str(local))
    await page_message(page, r"uploaded cam\.nc \(12\.0 MB\)")
    seen = await page.evaluate("window.progressSeen")
    assert any(0 < value < 1 for value in seen), seen  # the bar moved on before the end
    assert (realtime_service.program_dir / "cam.nc").read_bytes() == program
    await page.wait_for_selector("#program-list li.selected[data-name='cam.nc']", timeout=WAIT_MS)
    assert await page.text_content("#lines-shown") == f"lines 1–200 of {len(lines)}"
    assert await page.locator("#program-text li").count() == 200
    await page.click("#lines-next")
    await page.wait_for_function(
        "() => document.querySelector('#lines-shown').textContent.startsWith('lines 201–400')",
        timeout=WAIT_MS)
    assert await page.text_content("#program-text li:first-child") == lines[200]
    await page.fill("#lines-goto", "300000")
    await page.dispatch_event("#lines-goto", "change")
    await page.wait_for_function(
        "() => document.querySelector('#lines-shown').textContent.startsWith('lines 299950–')",
        timeout=WAIT_MS)
    assert await page.text_content("#program-text li:nth-child(51)") == lines[300_000 - 1]


async def test_cancel_leaves_nothing(page: Any, web: WebProcess,
                                     realtime_service: ServiceProcess, tmp_path: Path) -> None:
    local = tmp_path / "long.nc"
    local.write_bytes(g1_program(60_000_000))  # fifteen slices: time to cancel after one
    await open_page(page, web.url, "program")
    await page.set_input_files("#upload-input", str(local))
    await page.wait_for_function("() => document.querySelector('#upload-progress').value > 0",
                                 timeout=WAIT_MS)
    await page.click("#upload-cancel")
    await page_message(page, r"upload of long\.nc cancelled")
    await asyncio.to_thread(realtime_service.wait_for_log, r"upload of 'long\.nc' abandoned",
                            20.0)
    assert leftovers(realtime_service.program_dir) == []
    assert not (realtime_service.program_dir / "long.nc").exists()
    assert await page.is_hidden("#upload")



async def test_the_window_follows_the_running_program(page: Any, web: WebProcess,
                                                      tmp_path: Path) -> None:
    local = tmp_path / "steps.nc"  # 1000 steps of 0.1 mm at 20 mm/s: 5 s, past the window
    local.write_text("".join(f"N{n} G1 X{n * 0.1:.1f} F1200\n" for n in range(1, 1001)) + "M30\n")
    await open_page(page, web.url, "program")
    await page.set_input_files("#upload-input", str(local))
    await page.wait_for_selector("#program-list li.selected[data-name='steps.nc']",
                                 timeout=WAIT_MS)
    assert await page.text_content("#lines-shown") == "lines 1–200 of 1001"
    await page.click("#start-program")
    # the run leaves lines 1-200: the window moves on and marks the current line in it
    await page.wait_for_function("""() => {
        const shown = document.querySelector('#lines-shown').textContent;
        return !shown.startsWith('lines 1–') && document.querySelector('#program-text li.current');
    }""", timeout=WAIT_MS)
