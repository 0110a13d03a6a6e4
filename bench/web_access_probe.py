"""The access holes of issue 35 in cnc-web, measured: run before and after a change.

    .venv/bin/python -m bench.web_access_probe

A service with keys, cnc-web with an admin key and a users file (monitor, operator,
admin), loopback only, as the attack on a fresh clone had it; a second cnc-web without a
users file (``make run``'s defaults) for the Host check. It prints one line per figure:

* 3: the status of an operator's and an admin's upload over a stored program;
* 4: ``Host: evil.example:PORT``: the status of ``GET /api/session`` (and the role it
  gives) and of a write with the token it gave;
* 9: the status of a read with a cookie after sign-out, after its role's password
  changed, after its role was removed;
* 5: another session's read latency (p50, max) while 4 clients send wrong passwords for
  ``SECONDS``; the attempts answered 401 and 429; cnc-web's RSS before and its peak;
* 11: of ``HALF_SENT`` connections that send half a request, how many are still open
  ``HEADER_WAIT_S`` later, how many were refused, and an established session's read.
"""

from __future__ import annotations

import asyncio
import statistics
import tempfile
import time
from pathlib import Path
from typing import Any

import aiohttp

from cnc_objects.clients.web.users import WebRole, WebUsers, save_users
from cnc_objects.testing.process import start_service
from cnc_objects.testing.web import WebProcess, serving_web

PASSWORDS = {WebRole.MONITOR: "look-only", WebRole.OPERATOR: "runs-programs",
             WebRole.ADMIN: "keeps-the-store"}
SECONDS = 4.0
HALF_SENT = 3000
HEADER_WAIT_S = 12.0  # beyond the header timeout's default (10 s)
READ = {"name": "ch1.mc_active_feed_override_r"}


def _rss_kib(web: WebProcess, field: str) -> int:
    for line in Path(f"/proc/{web.process.pid}/status").read_text().splitlines():
        if line.startswith(field + ":"):
            return int(line.split()[1])
    return -1


async def _signed_in(url: str, role: WebRole) -> tuple[aiohttp.ClientSession, str, str]:
    http = aiohttp.ClientSession(cookie_jar=aiohttp.CookieJar(unsafe=True))
    async with http.post(url + "/api/login", json={"role": role.label,
                                                   "password": PASSWORDS[role]}) as reply:
        assert reply.status == 200, await reply.text()
    async with http.get(url + "/api/session") as reply:
        csrf = (await reply.json())["csrf"]
    cookie = next(c.value for c in http.cookie_jar if c.key == "cnc_web_session")
    return http, csrf, cookie


async def _status(url: str, cookie: str) -> int:
    async with aiohttp.ClientSession() as http, http.get(
            url + "/api/read", params=READ, headers={"Cookie": f"cnc_web_session={cookie}"}) as r:
        return r.status


async def _upload(http: aiohttp.ClientSession, url: str, csrf: str) -> int:
    form = aiohttp.FormData()
    form.add_field("file", b"N10 G1 X1 F600\nN20 M30\n", filename="busy.nc")
    async with http.post(url + "/api/programs", data=form, headers={"X-CSRF-Token": csrf}) as r:
        return r.status


async def holes_3_and_9(url: str, users: WebUsers, users_path: Path) -> None:
    operator, op_csrf, op_cookie = await _signed_in(url, WebRole.OPERATOR)
    admin, ad_csrf, ad_cookie = await _signed_in(url, WebRole.ADMIN)
    monitor, _, mo_cookie = await _signed_in(url, WebRole.MONITOR)
    print(f"3  upload over busy.nc: operator {await _upload(operator, url, op_csrf)}, "
          f"admin {await _upload(admin, url, ad_csrf)}")
    async with operator.post(url + "/api/logout") as reply:
        assert reply.status == 200
    users.set_password(WebRole.MONITOR, "a-new-one")
    users.remove(WebRole.ADMIN)
    save_users(users_path, users)
    print(f"9  read with the old cookie: after sign-out {await _status(url, op_cookie)}, "
          f"password changed {await _status(url, mo_cookie)}, "
          f"role removed {await _status(url, ad_cookie)}")
    for http in (operator, admin, monitor):
        await http.close()


async def hole_4(open_url: str) -> None:
    port = open_url.rsplit(":", 1)[1]
    evil = {"Host": f"evil.example:{port}"}
    async with aiohttp.ClientSession(cookie_jar=aiohttp.CookieJar(unsafe=True)) as http:
        async with http.get(open_url + "/api/session", headers=evil) as reply:
            status, body = reply.status, await reply.json()
        csrf = body.get("csrf")
        async with http.post(open_url + "/api/write", headers=evil | {"X-CSRF-Token": str(csrf)},
                             json={"name": "ch1.mc_command_feed_override_w", "value": 500}) as r:
            write_status = r.status
    print(f"4  Host evil.example: GET /api/session {status} (role {body.get('role')}), "
          f"write {write_status}")


async def hole_5(url: str, web: WebProcess) -> None:
    reader, _, _ = await _signed_in(url, WebRole.MONITOR)
    rss_before = _rss_kib(web, "VmRSS")
    answers: dict[int, int] = {}
    stop = time.monotonic() + SECONDS

    async def attacker() -> None:
        async with aiohttp.ClientSession() as http:
            while time.monotonic() < stop:
                async with http.post(url + "/api/login",
                                     json={"role": "operator", "password": "guess"}) as reply:
                    answers[reply.status] = answers.get(reply.status, 0) + 1

    latencies_ms: list[float] = []

    async def reads() -> None:
        while time.monotonic() < stop:
            t0 = time.perf_counter()
            async with reader.get(url + "/api/read", params=READ) as reply:
                assert reply.status == 200, await reply.text()
            latencies_ms.append((time.perf_counter() - t0) * 1000)

    await asyncio.gather(reads(), *(attacker() for _ in range(4)))
    await reader.close()
    print(f"5  another client's request during 4 parallel wrong sign-ins: p50 "
          f"{statistics.median(latencies_ms):.1f} ms, max {max(latencies_ms):.0f} ms "
          f"({len(latencies_ms)} in {SECONDS:g} s); sign-in answers {dict(sorted(answers.items()))}; "
          f"RSS {rss_before // 1024} MiB before, peak {_rss_kib(web, 'VmHWM') // 1024} MiB")


async def hole_11(url: str) -> None:
    host, port = url.removeprefix("http://").split(":")
    async with aiohttp.ClientSession(connector=aiohttp.TCPConnector(limit=1)) as http:
        async with http.get(url + "/api/session") as reply:  # an established connection
            await reply.read()
        held: list[tuple[asyncio.StreamReader, asyncio.StreamWriter]] = []
        failed = 0
        for _ in range(HALF_SENT):
            try:
                r, w = await asyncio.open_connection(host, int(port))
                w.write(f"GET /api/session HTTP/1.1\r\nHost: {host}:{port}\r\n".encode())
                held.append((r, w))
            except OSError:
                failed += 1
        await asyncio.sleep(0.5)
        refused = sum(1 for r, _ in held if r.at_eof() or _answered(r))
        t0 = time.perf_counter()
        async with http.get(url + "/api/session") as reply:
            during = f"{reply.status} in {(time.perf_counter() - t0) * 1000:.0f} ms"
        await asyncio.sleep(HEADER_WAIT_S)
        still_open = sum(1 for r, _ in held if not r.at_eof() and not _answered(r))
        print(f"11 {HALF_SENT} half-sent requests: {failed} failed to connect, {refused} answered "
              f"at once (503) or closed, {still_open} still open after {HEADER_WAIT_S:g} s; "
              f"an established session's read meanwhile: {during}")
        for _, w in held:
            w.close()


def _answered(reader: asyncio.StreamReader) -> bool:
    """True when the server wrote something (the 503) on this connection."""
    return bool(reader._buffer)  # type: ignore[attr-defined]  # no public peek


def main() -> None:
    """Measure every figure and print it."""
    with tempfile.TemporaryDirectory() as scratch:
        programs = Path(scratch) / "programs"
        programs.mkdir()
        (programs / "busy.nc").write_bytes(b"N10 G1 X100 F60\nN20 M30\n")
        users = WebUsers()
        for role, password in PASSWORDS.items():
            users.set_password(role, password)
        users_path = Path(scratch) / "web-users.json"
        save_users(users_path, users)
        service = start_service(keys=True, program_dir=programs)
        try:
            assert service.keys is not None
            keys: dict[str, Any] = {"key": service.keys.client("admin"),
                                    "server_key": service.keys.server_key}
            with serving_web(service.endpoint, users_file=users_path, **keys) as web:
                asyncio.run(holes_3_and_9(web.url, users, users_path))
            with serving_web(service.endpoint, **keys) as web:
                asyncio.run(hole_4(web.url))
            for role, password in PASSWORDS.items():
                users.set_password(role, password)
            save_users(users_path, users)
            with serving_web(service.endpoint, users_file=users_path, **keys) as web:
                asyncio.run(hole_5(web.url, web))
            with serving_web(service.endpoint, **keys) as web:
                asyncio.run(hole_11(web.url))
        finally:
            service.stop()


if __name__ == "__main__":
    main()
