"""cnc-web over HTTP in tests: a client session as a browser's (Origin, cookies) and JSON requests."""

from __future__ import annotations

from typing import Any

import aiohttp

WAIT_S = 20.0


def browser_session() -> aiohttp.ClientSession:
    """An HTTP client that keeps cookies as a browser does, also for an IP address host."""
    # unsafe: accept the session cookie of an IP address host (127.0.0.1)
    return aiohttp.ClientSession(cookie_jar=aiohttp.CookieJar(unsafe=True))


async def json_request(http: aiohttp.ClientSession, method: str, url: str,
                       csrf: str | None = None, **kwargs: Any) -> tuple[int, dict[str, Any]]:
    """``(status, JSON body)`` of one request, with the CSRF token when one is given."""
    headers = {"X-CSRF-Token": csrf} if csrf else {}
    async with http.request(method, url, headers=headers, **kwargs) as response:
        return response.status, await response.json()
