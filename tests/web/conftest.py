"""Fixtures of the cnc-web tests: a service on the real-time clock (positions move at the
pace a browser sees), cnc-web in front of it, a users file, and Debian's Chromium driven
by Playwright (skipped, saying why, where either is missing)."""

from __future__ import annotations

import shutil
from collections.abc import AsyncIterator, Iterator
from pathlib import Path
from typing import Any

import pytest

from cnc_objects.clients.web.users import WebRole, WebUsers, save_users
from cnc_objects.testing import ServiceProcess
from cnc_objects.testing.process import start_service
from cnc_objects.testing.web import WebProcess, serving_web

CHROMIUM_PATHS = ("/usr/bin/chromium", "/usr/bin/chromium-browser")
PASSWORDS = {WebRole.MONITOR: "look-only", WebRole.OPERATOR: "runs-programs"}
VIEWPORT = {"width": 1366, "height": 768}


@pytest.fixture
def realtime_service(tmp_path_factory: pytest.TempPathFactory) -> Iterator[ServiceProcess]:
    """A service of this test on the real-time clock."""
    service = start_service("--clock", "realtime",
                            program_dir=tmp_path_factory.mktemp("cnc-web-programs"))
    try:
        yield service
    finally:
        service.stop()


@pytest.fixture
def web(realtime_service: ServiceProcess) -> Iterator[WebProcess]:
    """cnc-web without a users file: no sign-in, every browser an operator."""
    with serving_web(realtime_service.endpoint) as running:
        yield running


@pytest.fixture
def users_file(tmp_path: Path) -> Path:
    """A users file with a password for monitor and operator."""
    users = WebUsers()
    for role, password in PASSWORDS.items():
        users.set_password(role, password)
    path = tmp_path / "web-users.json"
    save_users(path, users)
    return path


@pytest.fixture
def signed_web(realtime_service: ServiceProcess, users_file: Path) -> Iterator[WebProcess]:
    """cnc-web with sign-in (``users_file``)."""
    with serving_web(realtime_service.endpoint, users_file=users_file) as running:
        yield running


def chromium_path() -> str:
    """Debian's chromium, or the test is skipped saying why."""
    for path in CHROMIUM_PATHS:
        if shutil.which(path):
            return path
    pytest.skip("Debian's chromium is not installed (apt-get install chromium; .ci/run does)")


@pytest.fixture
async def page() -> AsyncIterator[Any]:
    """A fresh Chromium page at 1366x768 whose script errors fail the test."""
    executable = chromium_path()
    playwright_api = pytest.importorskip("playwright.async_api",
                                         reason="playwright is not installed (the test extra)")
    async with playwright_api.async_playwright() as driver:
        browser = await driver.chromium.launch(executable_path=executable,
                                               args=["--no-sandbox", "--disable-gpu"])
        try:
            context = await browser.new_context(viewport=VIEWPORT)
            opened = await context.new_page()
            errors: list[str] = []
            opened.on("pageerror", lambda exc: errors.append(str(exc)))
            yield opened
            assert errors == [], f"script errors on the page: {errors}"
        finally:
            await browser.close()
