"""Screenshots of every cnc-web page into docs/ (docs/web-<page>.png), for docs/web.md.

    .venv/bin/python tools/web_screenshots.py [--out docs] [--chromium /usr/bin/chromium]

Starts its own service (realtime clock) and cnc-web on free loopback ports, uploads
docs/examples/part.nc, contour-lookahead.nc and check-syntax.nc, and shows each page with
something on it: the pocket running (in G54, with its planned path), the syntax check's
errors on their lines, the look-ahead's elements and speed profile, jog and MDI with a
channel in ERROR, the tool list and zero offsets, alarms and their history, watched
objects. Needs Debian's
chromium and the test extra (playwright).
"""

from __future__ import annotations

import argparse
import asyncio
import tempfile
from pathlib import Path
from typing import Any

from playwright.async_api import Page, async_playwright

from cnc_objects.testing.process import start_service
from cnc_objects.testing.web import serving_web

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = ROOT / "docs" / "examples"
VIEWPORT = {"width": 1366, "height": 768}
WAIT_MS = 60_000


async def _show(page: Page, url: str, name: str) -> None:
    await page.goto(f"{url}/#{name}")
    await page.wait_for_selector("body[data-ready='1']", timeout=WAIT_MS)


async def _until(page: Page, script: str) -> None:
    await page.wait_for_function(script, timeout=WAIT_MS)


async def _shots(url: str, out: Path, chromium: str) -> list[Path]:
    made = []
    async with async_playwright() as driver:
        browser = await driver.chromium.launch(executable_path=chromium, args=["--no-sandbox"])
        page = await browser.new_page(viewport=VIEWPORT)  # type: ignore[arg-type]

        async def shot(name: str) -> None:
            path = out / f"web-{name}.png"
            await page.screenshot(path=str(path))
            made.append(path)

        await _show(page, url, "tools")  # an offset for G54 and a tool, as an operator sets them
        await _until(page, "() => document.querySelectorAll('#offset-table tbody tr').length > 0")
        row = page.locator("#offset-table tbody tr[data-group='1'] input")
        await row.nth(0).fill("20")
        await row.nth(1).fill("10")
        await page.click("#offset-table tbody tr[data-group='1'] button")
        await _until(page, "() => /G54 written/.test(document.querySelector('#message').textContent)")
        tool = page.locator("#tool-table tbody tr[data-d='4'] input")
        await tool.nth(0).check()
        await tool.nth(1).fill("3")
        await tool.nth(2).fill("55.5")
        await page.click("#tool-table tbody tr[data-d='4'] button")
        await _until(page, "() => /wz\\[4\\] written/.test(document.querySelector('#message').textContent)")
        await shot("tools")

        await _show(page, url, "program")
        await page.set_input_files("#upload-input", [str(EXAMPLES / n) for n in (
            "check-syntax.nc", "contour-lookahead.nc", "pocket-la-on.nc")])
        await page.wait_for_selector("#program-list li.selected", timeout=WAIT_MS)
        await page.click("#program-list li[data-name='check-syntax.nc']")
        await _until(page, "() => document.querySelectorAll('#program-text li').length > 5")
        await page.click("#check-program")
        await page.wait_for_selector("#program-text li.error", timeout=WAIT_MS)
        await shot("check")

        await page.click("#program-list li[data-name='pocket-la-on.nc']")
        await _until(page, "() => document.querySelector('#program-name').textContent === 'pocket-la-on.nc'")
        await _until(page, "() => document.querySelector('#path-planned').getAttribute('points')")
        await page.click("#start-program")
        await _until(page, "() => document.querySelector('#path-live').getAttribute('points')"
                           ".split(' ').length > 40")
        await shot("program")
        await _show(page, url, "machine")
        await _until(page, "() => /ACTIVE/.test(document.querySelector('#channels').textContent)")
        await shot("machine")
        await page.click("[data-command='reset']")  # the pocket needs minutes: end it here
        await _until(page, "() => !/ACTIVE|HOLD/.test(document.querySelector('#channels').textContent)")

        await _show(page, url, "lookahead")
        await page.goto(f"{url}/#program")
        await page.click("#program-list li[data-name='contour-lookahead.nc']")
        await _until(page, "() => document.querySelector('#program-name').textContent === "
                           "'contour-lookahead.nc'")
        await page.click("#select-program")
        await page.goto(f"{url}/#lookahead")
        await page.click("#profile-draw")
        await _until(page, "() => document.querySelector('#profile-v').getAttribute('points')")
        await page.click("#lookahead-marked")  # the dry run logged the marked area
        await page.wait_for_selector("#lookahead-table tbody tr", timeout=WAIT_MS)
        await page.goto(f"{url}/#program")  # the speed profile of the pocket: more to see
        await page.click("#program-list li[data-name='pocket-la-on.nc']")
        await _until(page, "() => document.querySelector('#program-name').textContent === "
                           "'pocket-la-on.nc'")
        await page.goto(f"{url}/#lookahead")
        await page.click("#profile-draw")
        await _until(page, "() => document.querySelector('#profile-name').textContent === "
                           "'pocket-la-on.nc'")
        await shot("lookahead")

        await _show(page, url, "mdi")
        await page.select_option("#jog-mode", "continuous")
        await page.click("#home-all")
        await _until(page, "() => [...document.querySelectorAll('#jog td[data-format=referenced]')]"
                           ".every(td => td.textContent === 'yes')")
        # a block in G54, then one with an error, then one refused in ERROR (naming Reset)
        waits = ("() => document.querySelector('#jog td[data-value$=command_position_pcs]')"
                 ".textContent === '10.0000'",
                 "() => /ERROR/.test(document.querySelector('#mdi-state').textContent)",
                 "() => /Reset/.test(document.querySelector('#message').textContent)")
        for block, done in zip(("G54 G90 G1 X10 Y10 F3000", "G1 Q7", "G1 X1"), waits, strict=True):
            await page.fill("#mdi-input", block)
            await page.click("#mdi-form button")
            await _until(page, done)
            print(f"MDI {block}: {await page.text_content('#message')}")
        await shot("mdi")
        await _show(page, url, "alarms")
        await page.click("#alarm-ack-all")
        await _until(page, "() => /acknowledged/.test(document.querySelector('#message').textContent)")
        await _until(page, "() => document.querySelectorAll('#alarm-history tbody tr').length > 0")
        await shot("alarms")
        await _show(page, url, "mdi")
        await page.click("#mdi-reset")
        await _until(page, "() => !/ERROR/.test(document.querySelector('#mdi-state').textContent)")

        await _show(page, url, "objects")
        await page.fill("#object-pattern", "ch1.ax1.*position*")
        await page.click("#object-search button")
        await page.wait_for_selector("#object-table tbody tr", timeout=WAIT_MS)
        buttons = page.locator("#object-table tbody tr button")
        for k in range(min(3, await buttons.count())):
            await buttons.nth(k).click()
        await _until(page, "() => document.querySelectorAll('#watch-table td[data-watch]').length >= 3")
        await shot("objects")
        await browser.close()
    return made


def main(argv: list[str] | None = None) -> None:
    """Make the screenshots."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--out", type=Path, default=ROOT / "docs")
    parser.add_argument("--chromium", default="/usr/bin/chromium")
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        service = start_service("--clock", "realtime", program_dir=Path(tmp) / "programs")
        try:
            with serving_web(service.endpoint) as web:
                made: list[Any] = asyncio.run(_shots(web.url, args.out, args.chromium))
        finally:
            service.stop()
    for path in made:
        print(path.relative_to(ROOT) if path.is_relative_to(ROOT) else path)


if __name__ == "__main__":
    main()
