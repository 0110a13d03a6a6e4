"""cnc-web's pages in Chromium (Playwright): open a page, read its message line."""

from __future__ import annotations

from typing import Any

WAIT_MS = 30_000


async def open_page(page: Any, url: str, hash_: str = "machine") -> None:
    await page.goto(f"{url}/#{hash_}")
    await page.wait_for_selector("body[data-ready='1']", timeout=WAIT_MS)


async def page_message(page: Any, pattern: str) -> str:
    """Wait until the message line matches ``pattern``; return its text."""
    await page.wait_for_function(
        "p => new RegExp(p).test(document.querySelector('#message').textContent)",
        arg=pattern, timeout=WAIT_MS)
    return str(await page.text_content("#message"))
