"""Programs as big as CAM writes them through cnc-web: the chunked upload from a page
(slices forwarded to the service's chunked upload as they come) and the program view's
window of lines, against a real service and a real cnc-web over HTTP."""

from __future__ import annotations

import asyncio
import hashlib
import time
from pathlib import Path
from typing import Any
from urllib.parse import urlsplit

import aiohttp

from cnc_objects.clients.web.users import WebRole
from cnc_objects.testing import ServiceProcess
from cnc_objects.testing.web import WebProcess, serving_web
from tests.limits.wire import limited_service
from tests.support.uploads import (
    g1_program,
    leftovers,
    peak_rss_bytes,
    write_big_program,
)
from tests.support.web_http import browser_session, json_request

from .conftest import PASSWORDS

SLICE_BYTES = 4 << 20  # what the page sends per request
ABANDONED_S = 20.0  # wall time for an abandon to reach the service's log on a busy machine


async def _admin(http: aiohttp.ClientSession, web: WebProcess) -> str:
    """The CSRF token of the open server's session (admin on loopback)."""
    _, session = await json_request(http, "GET", web.url + "/api/session")
    assert session["role"] == "admin"
    return str(session["csrf"])


async def _open(http: aiohttp.ClientSession, web: WebProcess, csrf: str, name: str,
                size_bytes: int) -> tuple[int, dict[str, Any]]:
    return await json_request(http, "POST", web.url + "/api/uploads", csrf,
                       json={"name": name, "size_bytes": size_bytes})


async def _slice(http: aiohttp.ClientSession, web: WebProcess, csrf: str, upload: str,
                 at: int, data: bytes) -> tuple[int, dict[str, Any]]:
    return await json_request(http, "PUT", f"{web.url}/api/uploads/{upload}?at={at}", csrf, data=data)


async def _upload_file(http: aiohttp.ClientSession, web: WebProcess, csrf: str, name: str,
                       path: Path) -> list[int]:
    """Upload ``path`` as the page does, slice by slice; the bytes received after each."""
    size = path.stat().st_size
    status, opened = await _open(http, web, csrf, name, size)
    assert status == 200, opened
    received = []
    with path.open("rb") as f:
        while data := f.read(opened["slice_bytes"]):
            status, body = await _slice(http, web, csrf, opened["upload"], received[-1]
                                        if received else 0, data)
            assert status == 200, body
            received.append(body["received_bytes"])
    status, body = await json_request(http, "POST", f"{web.url}/api/uploads/{opened['upload']}/commit",
                               csrf)
    assert (status, body) == (200, {"name": name, "size_bytes": size})
    return received


async def test_a_program_over_the_old_4_mb_lands_whole_and_its_view_is_a_window(
        web: WebProcess, realtime_service: ServiceProcess, tmp_path: Path) -> None:
    program = g1_program(12_000_000)  # three slices; the old upload refused it (4 MiB)
    local = tmp_path / "cam.nc"
    local.write_bytes(program)
    lines = program.decode().splitlines()
    async with browser_session() as http:
        csrf = await _admin(http, web)
        received = await _upload_file(http, web, csrf, "cam.nc", local)
        assert received == [SLICE_BYTES, 2 * SLICE_BYTES, len(program)]
        stored = realtime_service.program_dir / "cam.nc"
        assert hashlib.sha256(stored.read_bytes()).digest() == hashlib.sha256(program).digest()
        assert leftovers(realtime_service.program_dir) == []
        _, listing = await json_request(http, "GET", web.url + "/api/programs")
        assert [(p["name"], p["size_bytes"]) for p in listing["programs"]] == \
            [("cam.nc", len(program))]

        for first in (1, 200_000, len(lines) - 99):
            status, window = await json_request(http, "GET", web.url + "/api/programs/cam.nc/lines",
                                         params={"first": first, "count": 100})
            assert status == 200
            assert window["total_lines"] == len(lines)
            assert window["lines"] == lines[first - 1:first + 99], first
        status, window = await json_request(http, "GET", web.url + "/api/programs/cam.nc/lines",
                                     params={"first": len(lines) + 1, "count": 100})
        assert (status, window["lines"], window["total_lines"]) == (200, [], len(lines))
        status, body = await json_request(http, "GET", web.url + "/api/programs/cam.nc/lines",
                                   params={"first": 1, "count": 1001})
        assert status == 400 and "'count' 1..1000" in body["error"]
        status, body = await json_request(http, "GET", web.url + "/api/programs/none.nc/lines")
        assert status == 400 and "no program 'none.nc'" in body["error"]


async def _drop_mid_slice(web: WebProcess, http: aiohttp.ClientSession, csrf: str,
                          upload: str, sent_bytes: int) -> None:
    """Send a slice's headers (4 MiB announced) and ``sent_bytes`` of it, then close the
    connection: what a tab closed mid-slice does."""
    url = urlsplit(web.url)
    cookies = "; ".join(f"{c.key}={c.value}" for c in http.cookie_jar)
    reader, writer = await asyncio.open_connection(url.hostname, url.port)
    writer.write((f"PUT /api/uploads/{upload}?at=0 HTTP/1.1\r\nHost: {url.netloc}\r\n"
                  f"Cookie: {cookies}\r\nX-CSRF-Token: {csrf}\r\n"
                  f"Content-Length: {SLICE_BYTES}\r\n\r\n").encode() + b"N1 G1 X1\n" * (
                      sent_bytes // 9))
    await writer.drain()
    writer.close()
    await writer.wait_closed()


async def test_a_dropped_or_forgotten_upload_leaves_nothing(
        realtime_service: ServiceProcess) -> None:
    service = realtime_service
    with serving_web(service.endpoint, options=["--upload-idle", "1"]) as web:
        async with browser_session() as http:
            csrf = await _admin(http, web)
            # the connection drops mid-slice: abandoned at once
            _, opened = await _open(http, web, csrf, "dropped.nc", 3 * SLICE_BYTES)
            await _drop_mid_slice(web, http, csrf, opened["upload"], 1 << 20)
            await asyncio.to_thread(service.wait_for_log,
                                    r"upload of 'dropped.nc' abandoned after \d+ bytes", ABANDONED_S)
            status, body = await _slice(http, web, csrf, opened["upload"], 0, b"N1\n")
            assert status == 404 and "no such upload" in body["error"]
            # the tab closes between slices: abandoned when the next does not come (1 s)
            _, opened = await _open(http, web, csrf, "forgotten.nc", 2 * SLICE_BYTES)
            status, _ = await _slice(http, web, csrf, opened["upload"], 0, b"N1\n" * 1000)
            assert status == 200
            await asyncio.to_thread(service.wait_for_log,
                                    r"upload of 'forgotten.nc' abandoned after 3000 bytes",
                                    ABANDONED_S)
            # cancelled on the page
            _, opened = await _open(http, web, csrf, "cancelled.nc", 2 * SLICE_BYTES)
            await _slice(http, web, csrf, opened["upload"], 0, b"N1\n" * 1000)
            status, body = await json_request(http, "DELETE", f"{web.url}/api/uploads/{opened['upload']}",
                                       csrf)
            assert (status, body) == (200, {"ok": True})
            await asyncio.to_thread(service.wait_for_log,
                                    r"upload of 'cancelled.nc' abandoned after 3000 bytes",
                                    ABANDONED_S)
            assert leftovers(service.program_dir) == []
            _, listing = await json_request(http, "GET", web.url + "/api/programs")
            assert listing["programs"] == []


async def test_only_admin_uploads_with_its_csrf_token(signed_web: WebProcess,
                                                      web: WebProcess) -> None:
    async with browser_session() as http:
        status, _ = await json_request(http, "POST", signed_web.url + "/api/login",
                                json={"role": "operator",
                                      "password": PASSWORDS[WebRole.OPERATOR]})
        _, session = await json_request(http, "GET", signed_web.url + "/api/session")
        status, body = await _open(http, signed_web, session["csrf"], "p.nc", 100)
        assert status == 403
        assert body["error"] == ("ADS 0x704 INVALIDACCESS: role operator may not upload "
                                 "programs; admin may")
        status, body = await _slice(http, signed_web, session["csrf"], "any", 0, b"N1\n")
        assert status == 403 and "role operator may not upload programs" in body["error"]
    async with browser_session() as http:
        await _admin(http, web)
        status, body = await _open(http, web, "", "p.nc", 100)  # no CSRF token
        assert status == 403 and "CSRF" in body["error"]


async def test_over_the_limit_is_refused_in_the_services_words(tmp_path: Path) -> None:
    with limited_service(tmp_path, program_max_bytes=2_000_000) as service, \
            serving_web(service.endpoint) as web:
        async with browser_session() as http:
            csrf = await _admin(http, web)
            status, body = await _open(http, web, csrf, "big.nc", 2_000_001)
            assert status == 400
            assert body["error"] == (
                "ADS 0x705 INVALIDSIZE: program 'big.nc' has 2000001 bytes; the store takes "
                "at most 2000000 in one program ([limits] program_max_bytes)")
            status, body = await _open(http, web, csrf, "../x.nc", 10)
            assert status == 400 and "plain file name" in body["error"]
            # a page that sends more than it announced
            _, opened = await _open(http, web, csrf, "lies.nc", 10)
            status, body = await _slice(http, web, csrf, opened["upload"], 0, b"N1\n" * 10)
            assert status == 400 and "beyond the 10 bytes announced" in body["error"]
            await asyncio.to_thread(service.wait_for_log, r"upload of 'lies.nc' abandoned")
            assert leftovers(service.program_dir) == []
            _, listing = await json_request(http, "GET", web.url + "/api/programs")
            assert listing["programs"] == []


async def test_a_200_mb_program_through_cnc_web(realtime_service: ServiceProcess,
                                                web: WebProcess, tmp_path: Path) -> None:
    """The size CAM writes: 200 MB through cnc-web, slice by slice; cnc-web's memory does
    not grow with the program, and its view opens on a window of lines."""
    local = tmp_path / "finish.nc"
    digest = write_big_program(local)
    size = local.stat().st_size
    pid = web.process.pid
    async with browser_session() as http:
        csrf = await _admin(http, web)
        before = peak_rss_bytes(pid)
        started = time.perf_counter()
        await _upload_file(http, web, csrf, "finish.nc", local)
        elapsed_s = time.perf_counter() - started
        after = peak_rss_bytes(pid)
        stored = realtime_service.program_dir / "finish.nc"
        with stored.open("rb") as f:
            assert hashlib.file_digest(f, "sha256").digest() == digest
        open_ms = []
        for first in (3_000_000, 1, 5_000_000):
            opened = time.perf_counter()
            status, window = await json_request(http, "GET", web.url + "/api/programs/finish.nc/lines",
                                         params={"first": first, "count": 200})
            open_ms.append(round((time.perf_counter() - opened) * 1000))
            assert status == 200 and len(window["lines"]) == 200
            assert window["total_lines"] > 5_000_000
    print(f"\n200 MB through cnc-web: {size / elapsed_s / 1e6:.0f} MB/s, cnc-web peak RSS "
          f"{before / 1e6:.0f} -> {after / 1e6:.0f} MB; windows of 200 lines at lines "
          f"3 000 000, 1, 5 000 000 opened in {open_ms} ms")
    assert after - before < 50_000_000  # not the program's 200 MB
