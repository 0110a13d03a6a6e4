"""cnc-web's HTTP API and WebSocket without a browser, against a real service.

Sessions and CSRF, the service's refusals passed on in its words, sign-in per role with
the monitor refused by the web server, upload, one subscription per object for all
WebSockets, and the loopback-only rule without keys.
"""

from __future__ import annotations

import asyncio
import subprocess
import sys
from pathlib import Path
from typing import Any

import aiohttp

from cnc_objects.clients.web.users import WebRole
from cnc_objects.testing import ServiceProcess, serving
from cnc_objects.testing.web import WebProcess, serving_web
from tests.support.web_http import WAIT_S, browser_session, json_request

from .conftest import PASSWORDS


async def test_open_server_gives_an_admin_session_and_checks_csrf(web: WebProcess) -> None:
    """Without a users file every browser of this machine has the role the service gives
    loopback peers without keys: admin."""
    async with browser_session() as http:
        status, session = await json_request(http, "GET", web.url + "/api/session")
        assert status == 200
        assert session["role"] == "admin" and session["may_write"] is True
        assert session["sign_in_required"] is False
        write = {"name": "ch1.mc_command_feed_override_w", "value": 500}
        status, body = await json_request(http, "POST", web.url + "/api/write", json=write)
        assert status == 403 and "CSRF" in body["error"]
        status, body = await json_request(http, "POST", web.url + "/api/write", session["csrf"], json=write)
        assert (status, body) == (200, {"ok": True})
        status, body = await json_request(http, "GET", web.url + "/api/read",
                                   params={"name": "ch1.mc_active_feed_override_r"})
        assert body["value"] == 500


async def test_a_refusal_of_the_service_comes_back_in_its_words(web: WebProcess) -> None:
    async with browser_session() as http:
        _, session = await json_request(http, "GET", web.url + "/api/session")
        status, body = await json_request(http, "POST", web.url + "/api/write", session["csrf"],
                                   json={"name": "ch1.mc_command_feed_override_w", "value": 2000})
        assert status == 400
        assert body["error"] == "ADS 0x706 INVALIDDATA: feed override 200 % is outside 0..100 %"
        status, body = await json_request(http, "GET", web.url + "/api/read", params={"name": "ch1.nope"})
        assert status == 400 and body["error"].startswith("ADS 0x710 SYMBOLNOTFOUND")


async def test_without_a_session_cookie_the_api_is_refused(signed_web: WebProcess) -> None:
    async with browser_session() as http:
        status, session = await json_request(http, "GET", signed_web.url + "/api/session")
        assert session["role"] is None and session["sign_in_required"] is True
        assert session["roles"] == ["monitor", "operator"]
        status, body = await json_request(http, "GET", signed_web.url + "/api/machine")
        assert status == 401 and "not signed in" in body["error"]
        async with http.get(signed_web.url + "/ws") as response:
            assert response.status == 401
        http.cookie_jar.update_cookies({"cnc_web_session": "forged.value.sig"})
        status, _ = await json_request(http, "GET", signed_web.url + "/api/machine")
        assert status == 401


async def test_sign_in_per_role_and_the_monitor_is_refused_every_write(
        signed_web: WebProcess) -> None:
    async with browser_session() as http:
        status, body = await json_request(http, "POST", signed_web.url + "/api/login",
                                   json={"role": "monitor", "password": "wrong"})
        assert status == 401 and body["error"] == "wrong password for role monitor"
        status, _ = await json_request(http, "POST", signed_web.url + "/api/login",
                                json={"role": "monitor", "password": PASSWORDS[WebRole.MONITOR]})
        assert status == 200
        _, session = await json_request(http, "GET", signed_web.url + "/api/session")
        assert session["role"] == "monitor" and session["may_write"] is False
        csrf = session["csrf"]
        writes = [
            ("/api/write", {"name": "ch1.mc_command_feed_override_w", "value": 500}),
            ("/api/channel/1/start", {}), ("/api/channel/1/reset", {}),
            ("/api/channel/1/mdi", {"blocks": "G1 X1 F600"}),
            ("/api/channel/1/select", {"program": "p.nc"}),
            ("/api/channel/1/jog", {"axis": 1, "direction": 1}),
            ("/api/alarms/1/acknowledge", {}),
        ]
        for path, payload in writes:
            status, body = await json_request(http, "POST", signed_web.url + path, csrf, json=payload)
            assert status == 403, path
            assert body["error"].startswith("ADS 0x704 INVALIDACCESS: role monitor may not "), path
        form = aiohttp.FormData()
        form.add_field("file", b"N10 G1 X1 F600\n", filename="p.nc")
        status, body = await json_request(http, "POST", signed_web.url + "/api/programs", csrf, data=form)
        assert status == 403 and "role monitor may not upload programs" in body["error"]
        status, body = await json_request(http, "GET", signed_web.url + "/api/read",
                                   params={"name": "ch1.mc_active_feed_override_r"})
        assert (status, body["value"]) == (200, 1000)  # reads are allowed; nothing was written

        status, _ = await json_request(http, "POST", signed_web.url + "/api/login",
                                json={"role": "operator", "password": PASSWORDS[WebRole.OPERATOR]})
        _, session = await json_request(http, "GET", signed_web.url + "/api/session")
        status, body = await json_request(http, "POST", signed_web.url + "/api/write", session["csrf"],
                                   json={"name": "ch1.mc_command_feed_override_w", "value": 500})
        assert (status, body) == (200, {"ok": True})


async def test_upload_list_and_read_a_program(web: WebProcess,
                                              realtime_service: ServiceProcess) -> None:
    async with browser_session() as http:
        _, session = await json_request(http, "GET", web.url + "/api/session")
        form = aiohttp.FormData()
        form.add_field("file", b"N10 G1 X1 F600\nN20 M30\n", filename="up.nc")
        status, body = await json_request(http, "POST", web.url + "/api/programs", session["csrf"],
                                   data=form)
        assert (status, body) == (200, {"name": "up.nc", "size_bytes": 23})
        assert (realtime_service.program_dir / "up.nc").read_bytes() == b"N10 G1 X1 F600\nN20 M30\n"
        _, listing = await json_request(http, "GET", web.url + "/api/programs")
        assert [p["name"] for p in listing["programs"]] == ["up.nc"]
        _, text = await json_request(http, "GET", web.url + "/api/programs/up.nc")
        assert text["text"] == "N10 G1 X1 F600\nN20 M30\n"


async def test_syntax_check_returns_errors_with_their_lines(
        web: WebProcess, realtime_service: ServiceProcess) -> None:
    source = Path(__file__).resolve().parents[2] / "docs" / "examples" / "check-syntax.nc"
    async with browser_session() as http:
        _, session = await json_request(http, "GET", web.url + "/api/session")
        form = aiohttp.FormData()
        form.add_field("file", source.read_bytes(), filename="check-syntax.nc")
        await json_request(http, "POST", web.url + "/api/programs", session["csrf"], data=form)
        status, result = await json_request(http, "POST", web.url + "/api/channel/1/check",
                                     session["csrf"], json={"program": "check-syntax.nc"})
        assert status == 200
        assert [(e["line"], e["id"]) for e in result["errors"]] == [
            (5, 20113), (8, 20500), (11, 20310), (14, 20151), (17, 20121)]


async def test_every_websocket_shares_one_subscription_per_object(web: WebProcess) -> None:
    names = ["ch1.ax1.command_position_acs", "ch1.mc_active_state_r"]
    async with browser_session() as http:
        await json_request(http, "GET", web.url + "/api/session")
        sockets = [await http.ws_connect(web.url + "/ws") for _ in range(5)]
        try:
            for socket in sockets:
                await socket.send_json({"watch": names})
            for socket in sockets:  # each gets the current values
                seen: dict[str, Any] = {}
                while set(seen) != set(names):
                    message = await asyncio.wait_for(socket.receive_json(), WAIT_S)
                    seen.update(message.get("values", {}))
                assert seen["ch1.mc_active_state_r"] == 1  # DESELECTED: a fresh service
            _, stats = await json_request(http, "GET", web.url + "/api/stats")
            assert stats["subscriptions"] == len(names) and stats["sockets"] == 5
            await sockets[0].send_json({"watch": ["ch1.no_such_object"]})
            message = await asyncio.wait_for(sockets[0].receive_json(), WAIT_S)
            assert message["errors"]["ch1.no_such_object"].startswith("ADS 0x710")
        finally:
            for socket in sockets:
                await socket.close()
        async def all_gone() -> None:
            while (await json_request(http, "GET", web.url + "/api/stats"))[1]["subscriptions"]:
                await asyncio.sleep(0.05)
        await asyncio.wait_for(all_gone(), WAIT_S)  # nobody watches: unsubscribed


def test_without_a_key_it_serves_loopback_only(shared_service: ServiceProcess) -> None:
    run = subprocess.run(
        [sys.executable, "-m", "cnc_objects.clients.web.cli", "--endpoint",
         shared_service.endpoint, "--host", "0.0.0.0", "--port", "0"],
        capture_output=True, text=True, timeout=60, check=False)
    assert run.returncode == 2
    assert "without --key (the service's keys) cnc-web serves loopback only" in run.stderr


def test_cnc_web_users_set_writes_a_hashed_file(tmp_path: Path) -> None:
    path = tmp_path / "users.json"
    run = subprocess.run(
        [sys.executable, "-m", "cnc_objects.clients.cli", "web-users", "set", "operator",
         "--file", str(path)], input="s3cret\n", capture_output=True, text=True, timeout=60,
        check=False)
    assert run.returncode == 0, run.stderr
    text = path.read_text()
    assert "s3cret" not in text and "$argon2id$" in text
    assert path.stat().st_mode & 0o777 == 0o600
    from cnc_objects.clients.web.users import load_users

    users = load_users(path)
    assert users.verify(WebRole.OPERATOR, "s3cret") and not users.verify(WebRole.OPERATOR, "x")
    bad = subprocess.run(
        [sys.executable, "-m", "cnc_objects.clients.cli", "web-users", "set", "root",
         "--file", str(path)], input="x\n", capture_output=True, text=True, timeout=60,
        check=False)
    assert bad.returncode == 2 and "unknown role 'root'" in bad.stderr



async def test_the_web_servers_key_bounds_every_page(tmp_path: Path) -> None:
    """cnc-web with a monitor key: its operators' writes reach the service, which refuses
    them in its own words; reads work."""
    from cnc_objects.testing.process import start_service
    from cnc_objects.testing.web import serving_web

    service = start_service(keys=True, program_dir=tmp_path / "programs")
    try:
        assert service.keys is not None
        with serving_web(service.endpoint, key=service.keys.client("monitor"),
                         server_key=service.keys.server_key) as web:
            async with browser_session() as http:
                _, session = await json_request(http, "GET", web.url + "/api/session")
                assert session["role"] == "admin"  # no users file: this machine's browsers
                status, body = await json_request(
                    http, "POST", web.url + "/api/write", session["csrf"],
                    json={"name": "ch1.mc_command_feed_override_w", "value": 500})
                assert status == 400
                assert body["error"].startswith("ADS 0x704 INVALIDACCESS: role monitor may not "
                                                "write ch1.mc_command_feed_override_w")
                status, body = await json_request(http, "GET", web.url + "/api/read",
                                           params={"name": "ch1.mc_active_feed_override_r"})
                assert (status, body["value"]) == (200, 1000)
    finally:
        service.stop()


async def test_live_values_come_back_after_the_service_restarts(tmp_path: Path) -> None:
    from cnc_objects.clients import AsyncClient
    from cnc_objects.testing.process import start_service
    from cnc_objects.testing.web import free_port, serving_web

    endpoint = f"tcp://127.0.0.1:{free_port()}"
    service = start_service("--endpoint", endpoint, program_dir=tmp_path / "programs")
    name = "ch1.mc_active_feed_override_r"
    try:
        with serving_web(endpoint) as web:
            async with browser_session() as http:
                await json_request(http, "GET", web.url + "/api/session")
                async with http.ws_connect(web.url + "/ws") as socket:
                    await socket.send_json({"watch": [name]})
                    first = await asyncio.wait_for(socket.receive_json(), WAIT_S)
                    assert first["values"][name] == 1000
                    assert service.stop() == 0
                    service = start_service("--endpoint", endpoint,
                                            program_dir=tmp_path / "programs")
                    async with AsyncClient(endpoint) as client:
                        await client.write("ch1.mc_command_feed_override_w", 500)

                    async def override_500() -> None:
                        while (await socket.receive_json()).get("values", {}).get(name) != 500:
                            pass
                    await asyncio.wait_for(override_500(), WAIT_S)
    finally:
        service.stop()


async def test_an_alarm_is_listed_with_its_place_and_acknowledged_by_its_number(
    web: WebProcess,
) -> None:
    async with browser_session() as http:
        _, session = await json_request(http, "GET", web.url + "/api/session")
        csrf = session["csrf"]
        status, _ = await json_request(http, "POST", web.url + "/api/channel/1/reset", csrf, json={})
        assert status == 200
        status, _ = await json_request(http, "POST", web.url + "/api/channel/1/mdi", csrf,
                                json={"blocks": "G1 X1"})  # no feed: ISG 20008
        assert status == 200
        deadline = asyncio.get_running_loop().time() + WAIT_S
        while True:
            _, listed = await json_request(http, "GET", web.url + "/api/alarms")
            raised = [a for a in listed["alarms"] if a["id"] == 20008]
            if raised:
                break
            assert asyncio.get_running_loop().time() < deadline, listed
            await asyncio.sleep(0.05)
        alarm = raised[-1]
        assert (alarm["channel"], alarm["severity"], alarm["state"]) == (1, "error", "active")
        assert (alarm["file"], alarm["line"]) == ("MDI", 1) and alarm["column"] >= 1
        path = f"/api/alarms/{alarm['sequence']}/acknowledge"
        status, body = await json_request(http, "POST", web.url + path, csrf, json={})
        assert (status, body) == (200, {"ok": True})
        _, listed = await json_request(http, "GET", web.url + "/api/alarms")
        again = next(a for a in listed["alarms"] if a["sequence"] == alarm["sequence"])
        assert again["state"] == "acknowledged"  # an error stays active until RESET
        status, body = await json_request(http, "POST", web.url + "/api/alarms/999999/acknowledge",
                                   csrf, json={})
        assert status == 400 and body["error"].startswith("ADS 0x70c NOTFOUND: no alarm has")
        await json_request(http, "POST", web.url + "/api/channel/1/reset", csrf, json={})


async def test_a_rotary_axis_is_shown_in_degrees(tmp_path: Path) -> None:
    """Issue 39: the machine's axes carry their unit, degrees for a rotary axis."""
    with serving("--machine", "five-axis-ac", cwd=tmp_path) as service, \
            serving_web(service.endpoint, cwd=tmp_path) as five:
        async with browser_session() as http:
            await json_request(http, "GET", five.url + "/api/session")  # the session cookie
            status, body = await json_request(http, "GET", five.url + "/api/machine")
    assert status == 200
    first = body["channels"][0]["axes"]
    assert [(a["name"], a["unit"]) for a in first] == [
        ("X", "mm"), ("Y", "mm"), ("Z", "mm"), ("A", "°"), ("C", "°")]
