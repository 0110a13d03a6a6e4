"""cnc-web's access rules against the holes of issue 35, over HTTP against a real service.

Roles as the service has them (an upload needs admin), requests that do not name this
server (DNS rebinding), sign-in that neither stalls other users nor goes unlimited,
sessions that end at once, and the connection cap and header timeout.
"""

from __future__ import annotations

import asyncio
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import aiohttp
import pytest

from cnc_objects.clients.web.users import WebRole, WebUsers, save_users
from cnc_objects.testing import ServiceProcess
from cnc_objects.testing.web import WebProcess, serving_web
from tests.support.web_http import browser_session

from .conftest import PASSWORDS

WAIT_S = 20.0
COOKIE = "cnc_web_session"
READ = {"name": "ch1.mc_active_feed_override_r"}
OVERRIDE_WRITE = {"name": "ch1.mc_command_feed_override_w", "value": 500}


async def _json(http: aiohttp.ClientSession, method: str, url: str,
                headers: dict[str, str] | None = None, **kwargs: Any) -> tuple[int, dict[str, Any]]:
    async with http.request(method, url, headers=headers or {}, **kwargs) as response:
        return response.status, await response.json()


async def _sign_in(http: aiohttp.ClientSession, url: str, role: WebRole,
                   password: str) -> tuple[str, str]:
    """Sign ``http`` in; its CSRF token and its session cookie."""
    status, body = await _json(http, "POST", url + "/api/login",
                               json={"role": role.label, "password": password})
    assert status == 200, body
    _, session = await _json(http, "GET", url + "/api/session")
    cookie = next(c.value for c in http.cookie_jar if c.key == COOKIE)
    return session["csrf"], cookie


async def _read_with(url: str, cookie: str) -> int:
    """The status of a read that carries ``cookie``, from a browser without other state."""
    async with aiohttp.ClientSession() as http, http.get(
            url + "/api/read", params=READ, headers={"Cookie": f"{COOKIE}={cookie}"}) as reply:
        return reply.status


def _upload_form(text: bytes, name: str = "busy.nc") -> aiohttp.FormData:
    form = aiohttp.FormData()
    form.add_field("file", text, filename=name)
    return form


# ---------------------------------------------------------------- hole 3: roles

async def test_an_upload_needs_admin_as_on_the_service(
        realtime_service: ServiceProcess, tmp_path: Path) -> None:
    passwords = {WebRole.OPERATOR: "runs-programs", WebRole.ADMIN: "keeps-the-store"}
    users = WebUsers()
    for role, password in passwords.items():
        users.set_password(role, password)
    save_users(tmp_path / "users.json", users)
    stored = realtime_service.program_dir / "busy.nc"
    stored.write_bytes(b"N10 G1 X100 F60\nN20 M30\n")
    with serving_web(realtime_service.endpoint, users_file=tmp_path / "users.json") as web:
        async with browser_session() as operator, browser_session() as admin:
            op_csrf, _ = await _sign_in(operator, web.url, WebRole.OPERATOR,
                                        passwords[WebRole.OPERATOR])
            status, body = await _json(operator, "POST", web.url + "/api/programs",
                                       {"X-CSRF-Token": op_csrf}, data=_upload_form(b"M30\n"))
            assert status == 403
            assert body["error"] == ("ADS 0x704 INVALIDACCESS: role operator may not upload "
                                     "programs; admin may")
            assert stored.read_bytes() == b"N10 G1 X100 F60\nN20 M30\n"  # unchanged
            _, session = await _json(operator, "GET", web.url + "/api/session")
            assert (session["may_write"], session["may_upload"]) == (True, False)
            status, _ = await _json(operator, "POST", web.url + "/api/write",
                                    {"X-CSRF-Token": op_csrf}, json=OVERRIDE_WRITE)
            assert status == 200  # the operator still writes objects

            ad_csrf, _ = await _sign_in(admin, web.url, WebRole.ADMIN, passwords[WebRole.ADMIN])
            _, session = await _json(admin, "GET", web.url + "/api/session")
            assert (session["role"], session["may_upload"]) == ("admin", True)
            status, body = await _json(admin, "POST", web.url + "/api/programs",
                                       {"X-CSRF-Token": ad_csrf}, data=_upload_form(b"M30\n"))
            assert (status, body) == (200, {"name": "busy.nc", "size_bytes": 4})
            assert stored.read_bytes() == b"M30\n"


# ---------------------------------------------------------------- hole 4: Host and Origin

async def test_a_foreign_host_or_origin_is_refused_and_this_servers_names_work(
        web: WebProcess) -> None:
    port = web.url.rsplit(":", 1)[1]
    async with browser_session() as http:
        status, body = await _json(http, "GET", web.url + "/api/session",
                                   {"Host": f"evil.example:{port}"})
        assert status == 421 and "Host 'evil.example:" in body["error"]
        assert not any(c.key == COOKIE for c in http.cookie_jar)  # no session was given

        for host in (f"127.0.0.1:{port}", f"localhost:{port}", f"[::1]:{port}"):
            status, session = await _json(http, "GET", web.url + "/api/session", {"Host": host})
            assert status == 200, host
        csrf = session["csrf"]
        refused = [
            ({"Host": f"evil.example:{port}"}, 421),  # DNS rebinding: the cookie and token
            ({"Host": "127.0.0.1:1"}, 421),  # another port
            ({"Host": "127.0.0.1"}, 421),  # port 80
            ({"Origin": f"http://evil.example:{port}"}, 403),  # a page of another site
            ({"Origin": "null"}, 403),
            ({"Origin": "http://127.0.0.1:1"}, 403),
        ]
        for headers, expected in refused:
            status, body = await _json(http, "POST", web.url + "/api/write",
                                       {"X-CSRF-Token": csrf} | headers, json=OVERRIDE_WRITE)
            assert (status, "is not this server" in body["error"]) == (expected, True), headers
        _, value = await _json(http, "GET", web.url + "/api/read", params=READ)
        assert value["value"] == 1000  # no write got through

        for origin in (f"http://localhost:{port}", f"http://127.0.0.1:{port}"):
            status, body = await _json(http, "POST", web.url + "/api/write",
                                       {"X-CSRF-Token": csrf, "Origin": origin,
                                        "Host": origin.removeprefix("http://")},
                                       json=OVERRIDE_WRITE)
            assert (status, body) == (200, {"ok": True}), origin
        with pytest.raises(aiohttp.WSServerHandshakeError) as refused_socket:
            await http.ws_connect(web.url + "/ws", origin=f"http://evil.example:{port}")
        assert refused_socket.value.status == 403


# ---------------------------------------------------------------- hole 5: sign-in

async def test_sign_in_hashing_does_not_stall_other_sessions(signed_web: WebProcess) -> None:
    """4 wrong passwords at once (the address's attempts but one) while a monitor reads:
    its reads go on while the hashes are checked (on the event loop they waited for all)."""
    url = signed_web.url
    async with browser_session() as reader, aiohttp.ClientSession() as attacker:
        await _sign_in(reader, url, WebRole.MONITOR, PASSWORDS[WebRole.MONITOR])
        latencies_s: list[float] = []
        attempts = [asyncio.create_task(_json(attacker, "POST", url + "/api/login",
                                              json={"role": "operator", "password": f"guess{i}"}))
                    for i in range(4)]
        while not all(a.done() for a in attempts):
            started = time.perf_counter()
            status, _ = await _json(reader, "GET", url + "/api/read", params=READ)
            latencies_s.append(time.perf_counter() - started)
            assert status == 200
        assert [status for status, _ in await asyncio.gather(*attempts)] == [401] * 4
        assert len(latencies_s) >= 10, latencies_s
        assert max(latencies_s) < 2.0, latencies_s  # generous: the machine is shared


async def test_sign_in_attempts_over_the_limit_get_429_with_retry_after(
        signed_web: WebProcess) -> None:
    url = signed_web.url
    async with aiohttp.ClientSession() as http:
        # 6 at once: the address's 5 are taken on arrival (then hashed one by one), the
        # sixth is refused at once; the next comes well within a refill (12 s)
        attempts = [asyncio.create_task(_json(http, "POST", url + "/api/login",
                                              json={"role": "operator", "password": "guess"}))
                    for _ in range(6)]
        first, _ = await asyncio.wait(attempts, return_when=asyncio.FIRST_COMPLETED)
        assert [t.result()[0] for t in first] == [429]
        async with http.post(url + "/api/login", json={
                "role": "monitor", "password": PASSWORDS[WebRole.MONITOR]}) as reply:
            body = await reply.json()
            assert reply.status == 429  # refused before the hash: even the right password
            assert int(reply.headers["Retry-After"]) >= 1
            assert body["error"].startswith("too many sign-in attempts from address 127.0.0.1")
        assert sorted(status for status, _ in await asyncio.gather(*attempts)) == [401] * 5 + [429]
        status, body = await _json(http, "POST", url + "/api/login", json={"role": "root"})
        assert status == 400 and "unknown role 'root'" in body["error"]  # bad input first


def test_a_roles_attempts_are_limited_across_addresses() -> None:
    from cnc_objects.clients.web.signin import BucketRule, Buckets, SignInGate, TooManyAttempts

    now_s = [0.0]
    gate = SignInGate(per_address=BucketRule(burst=2, refill_s=10.0),
                      per_role=BucketRule(burst=3, refill_s=10.0))
    gate.addresses.clock = gate.roles.clock = lambda: now_s[0]
    try:
        for address in ("10.0.0.1", "10.0.0.2", "10.0.0.3"):
            gate.admit(address, "operator")
        with pytest.raises(TooManyAttempts, match="role operator: try again in 10 s") as over:
            gate.admit("10.0.0.4", "operator")
        assert over.value.retry_after_s == 10
        gate.admit("10.0.0.4", "monitor")  # another role has its own attempts
        now_s[0] = 10.0  # one attempt refilled
        gate.admit("10.0.0.4", "operator")
    finally:
        gate.close()
    buckets = Buckets(BucketRule(burst=1, refill_s=4.0), clock=lambda: now_s[0])
    buckets.take("a")
    assert buckets.wait_s("a") == 4.0 and buckets.wait_s("b") == 0.0


# ---------------------------------------------------------------- hole 9: sessions end

def _web_users(*args: str, password: str = "") -> None:
    run = subprocess.run([sys.executable, "-m", "cnc_objects.clients.cli", "web-users", *args],
                         input=password + "\n", capture_output=True, text=True, timeout=60,
                         check=False)
    assert run.returncode == 0, run.stderr


async def _ends(page: aiohttp.ClientWebSocketResponse) -> None:
    """The page's WebSocket is closed by cnc-web (its session ended)."""
    message = await asyncio.wait_for(page.receive(), WAIT_S)
    assert message.type in (aiohttp.WSMsgType.CLOSE, aiohttp.WSMsgType.CLOSED,
                            aiohttp.WSMsgType.ERROR), message
    await page.close()


async def test_sign_out_a_new_password_and_a_removed_role_end_sessions_at_once(
        signed_web: WebProcess, users_file: Path) -> None:
    url = signed_web.url
    async with browser_session() as a, browser_session() as b, browser_session() as c, browser_session() as d:
        _, signed_out = await _sign_in(a, signed_web.url, WebRole.OPERATOR,
                                       PASSWORDS[WebRole.OPERATOR])
        _, operator = await _sign_in(b, url, WebRole.OPERATOR, PASSWORDS[WebRole.OPERATOR])
        _, monitor = await _sign_in(c, url, WebRole.MONITOR, PASSWORDS[WebRole.MONITOR])
        assert [await _read_with(url, k) for k in (signed_out, operator, monitor)] == [200] * 3
        pages = [await http.ws_connect(url + "/ws") for http in (a, b, c)]  # open pages

        status, _ = await _json(a, "POST", url + "/api/logout")
        assert status == 200
        assert await _read_with(url, signed_out) == 401  # the cookie kept elsewhere: ended
        await _ends(pages[0])

        _web_users("set", "monitor", "--file", str(users_file), password="a-new-one")
        await _ends(pages[2])
        assert await _read_with(url, monitor) == 401
        assert await _read_with(url, operator) == 200  # another role's session goes on
        await _sign_in(d, url, WebRole.MONITOR, "a-new-one")

        _web_users("remove", "operator", "--file", str(users_file))
        await _ends(pages[1])
        assert await _read_with(url, operator) == 401
        _, session = await _json(b, "GET", url + "/api/session")
        assert session["role"] is None and session["roles"] == ["monitor"]


# ---------------------------------------------------------------- hole 11: connections

async def _half_sent(url: str) -> tuple[asyncio.StreamReader, asyncio.StreamWriter]:
    host, port = url.removeprefix("http://").split(":")
    reader, writer = await asyncio.open_connection(host, int(port))
    writer.write(f"GET /api/session HTTP/1.1\r\nHost: {host}:{port}\r\n".encode())  # no end
    return reader, writer


async def test_a_half_sent_request_is_closed_after_the_header_timeout(
        realtime_service: ServiceProcess) -> None:
    with serving_web(realtime_service.endpoint, options=["--header-timeout", "1"]) as web:
        async with browser_session() as http:
            await _json(http, "GET", web.url + "/api/session")
            async with http.ws_connect(web.url + "/ws") as socket:
                reader, writer = await _half_sent(web.url)
                started = time.monotonic()
                assert await asyncio.wait_for(reader.read(), WAIT_S) == b""  # closed, no answer
                assert time.monotonic() - started >= 0.9
                writer.close()
                # the WebSocket (a request under way) outlived the timeout
                await socket.send_json({"watch": [READ["name"]]})
                message = await asyncio.wait_for(socket.receive_json(), WAIT_S)
                assert message["values"][READ["name"]] == 1000


async def test_connections_over_the_cap_get_503_and_the_open_ones_go_on(
        realtime_service: ServiceProcess) -> None:
    with serving_web(realtime_service.endpoint, options=["--max-connections", "8"]) as web:
        connector = aiohttp.TCPConnector(limit=1)  # one kept-alive connection: the session's
        async with aiohttp.ClientSession(connector=connector,
                                         cookie_jar=aiohttp.CookieJar(unsafe=True)) as http:
            status, _ = await _json(http, "GET", web.url + "/api/session")
            assert status == 200
            held = [await _half_sent(web.url) for _ in range(10)]
            answers = [await asyncio.wait_for(reader.read(), WAIT_S) for reader, _ in held[7:]]
            assert all(a.startswith(b"HTTP/1.1 503 Service Unavailable\r\n") for a in answers)
            assert b"Retry-After: 1\r\n" in answers[0] and b"too many connections" in answers[0]
            status, body = await _json(http, "GET", web.url + "/api/read", params=READ)
            assert (status, body["value"]) == (200, 1000)  # the open session goes on
            for _, writer in held:
                writer.close()

            async def served_again() -> None:
                while True:
                    async with aiohttp.ClientSession() as fresh, fresh.get(
                            web.url + "/api/session") as reply:
                        if reply.status == 200:
                            return
            await asyncio.wait_for(served_again(), WAIT_S)
