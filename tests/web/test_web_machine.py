"""cnc-web's machine functions over HTTP and WebSockets, against a real service:
continuous jog held by the dead-man socket (released when the socket closes, when the
session ends, when the page stops renewing), handwheel, homing, the tool list and the
zero offset table with the service's roles, the alarm history with times,
acknowledge-all, and RESET after a manual block in ERROR.
"""

from __future__ import annotations

import asyncio
import contextlib
import time
from collections.abc import Callable
from typing import Any

import aiohttp

from cnc_objects.clients.web.jog_hold import RENEW_S
from cnc_objects.clients.web.users import WebRole
from cnc_objects.testing import ServiceProcess
from cnc_objects.testing.web import STOP_TIMEOUT_S, WebProcess, start_web
from tests.support.web_http import browser_session, json_request

from .conftest import PASSWORDS

WAIT_S = 20.0
AX1 = "ch1.ax1"


async def _open_session(http: aiohttp.ClientSession, url: str,
                        role: WebRole | None = None) -> str:
    """Sign in as ``role`` (None: the open server's session); the CSRF token."""
    if role is not None:
        status, _ = await json_request(http, "POST", url + "/api/login",
                                json={"role": role.label, "password": PASSWORDS[role]})
        assert status == 200
    _, session = await json_request(http, "GET", url + "/api/session")
    return str(session["csrf"])


class Live:
    """The values of watched objects, from cnc-web's live WebSocket."""

    def __init__(self, socket: aiohttp.ClientWebSocketResponse) -> None:
        self.socket = socket
        self.values: dict[str, Any] = {}

    async def until(self, name: str, wanted: Callable[[Any], bool],
                    timeout_s: float = WAIT_S) -> float:
        """Wait until ``name``'s value satisfies ``wanted``; the monotonic time it did."""
        deadline = time.monotonic() + timeout_s
        while not (name in self.values and wanted(self.values[name])):
            left = deadline - time.monotonic()
            assert left > 0, f"{name} is {self.values.get(name)!r} after {timeout_s} s"
            message = await self.socket.receive_json(timeout=left)
            self.values.update(message.get("values", {}))
        return time.monotonic()


async def _live(http: aiohttp.ClientSession, url: str, names: list[str]) -> Live:
    socket = await http.ws_connect(url.replace("http", "ws") + "/ws")
    await socket.send_json({"watch": names})
    return Live(socket)


async def _jog_socket(http: aiohttp.ClientSession, url: str,
                      csrf: str) -> aiohttp.ClientWebSocketResponse:
    socket = await http.ws_connect(url.replace("http", "ws") + f"/ws/jog?csrf={csrf}")
    hello = await socket.receive_json(timeout=WAIT_S)
    assert hello["held"] == [] and hello["renew_s"] > 0
    return socket


PRESS_X_PLUS = {"press": {"channel": 1, "axis": 1, "direction": 1, "rapid": False}}


async def test_continuous_jog_is_released_when_its_socket_closes(web: WebProcess) -> None:
    async with browser_session() as http, browser_session() as jog_http:
        csrf = await _open_session(http, web.url)
        jog_http.cookie_jar.update_cookies({c.key: c.value for c in http.cookie_jar})
        live = await _live(http, web.url, [f"{AX1}.manual_jog_plus_w", f"{AX1}.manual_moving_r",
                                           f"{AX1}.command_position_acs"])
        socket = await _jog_socket(jog_http, web.url, csrf)
        await socket.send_json(PRESS_X_PLUS)
        assert (await socket.receive_json(timeout=WAIT_S))["held"] == [f"{AX1}.manual_jog_plus_w"]
        await live.until(f"{AX1}.manual_moving_r", bool)
        await live.until(f"{AX1}.command_position_acs", lambda p: p > 0)
        # the page goes without a word: its connection drops (no close frame)
        closed_at = time.monotonic()
        await jog_http.close()
        released_at = await live.until(f"{AX1}.manual_jog_plus_w", lambda held: held is False)
        stopped_at = await live.until(f"{AX1}.manual_moving_r", lambda moving: moving is False)
        print(f"jog released {1000 * (released_at - closed_at):.0f} ms and the axis stood "
              f"{1000 * (stopped_at - closed_at):.0f} ms after the socket closed")
        assert released_at - closed_at < 1.0


async def test_continuous_jog_is_released_without_renewal_and_on_release(
        web: WebProcess) -> None:
    async with browser_session() as http:
        csrf = await _open_session(http, web.url)
        live = await _live(http, web.url, [f"{AX1}.manual_jog_plus_w"])
        socket = await _jog_socket(http, web.url, csrf)
        # released on the page's word (key-up)
        await socket.send_json(PRESS_X_PLUS)
        await live.until(f"{AX1}.manual_jog_plus_w", lambda held: held is True)
        await socket.send_json({"release": True})
        answers = [await socket.receive_json(timeout=WAIT_S) for _ in range(2)]
        assert answers[-1] == {"held": []}
        await live.until(f"{AX1}.manual_jog_plus_w", lambda held: held is False)
        # renewed, it stays held; a page that stops renewing loses it
        await socket.send_json(PRESS_X_PLUS)
        await socket.receive_json(timeout=WAIT_S)
        await socket.send_json({"renew": True})
        assert (await socket.receive_json(timeout=WAIT_S))["held"] == [f"{AX1}.manual_jog_plus_w"]
        pressed_at = time.monotonic()
        dropped = await socket.receive_json(timeout=WAIT_S)
        assert dropped["held"] == [] and "did not renew" in dropped["error"]
        assert time.monotonic() - pressed_at >= 0.9
        await live.until(f"{AX1}.manual_jog_plus_w", lambda held: held is False)
        await socket.send_json({"press": {"channel": 1, "axis": 0, "direction": 2}})
        assert "count from 1" in (await socket.receive_json(timeout=WAIT_S))["error"]


async def _renew(socket: aiohttp.ClientWebSocketResponse) -> None:
    """Renew the keys ``socket`` holds every ``RENEW_S``, as cnc-web's page does, until
    the socket closes."""
    with contextlib.suppress(ConnectionError):
        while not socket.closed:
            await socket.send_json({"renew": True})
            await asyncio.sleep(RENEW_S)


async def test_a_jog_ends_with_its_session_and_a_monitor_cannot_jog(
        signed_web: WebProcess) -> None:
    url = signed_web.url
    async with browser_session() as http, browser_session() as monitor:
        csrf = await _open_session(http, url, WebRole.OPERATOR)
        live = await _live(http, url, [f"{AX1}.manual_jog_minus_w"])
        socket = await _jog_socket(http, url, csrf)
        await socket.send_json({"press": {"channel": 1, "axis": 1, "direction": -1}})
        # held as a page holds it, renewed every RENEW_S (jog.js): a second sign-in takes
        # longer than HOLD_TIMEOUT_S on a busy machine, and the dead-man would end the jog
        renewing = asyncio.create_task(_renew(socket))
        try:
            await live.until(f"{AX1}.manual_jog_minus_w", lambda held: held is True)
            async with browser_session() as watcher:  # another session of the operator
                await _open_session(watcher, url, WebRole.OPERATOR)
                watching = await _live(watcher, url, [f"{AX1}.manual_jog_minus_w"])
                await watching.until(f"{AX1}.manual_jog_minus_w", lambda held: held is True)
                await json_request(http, "POST", url + "/api/logout", csrf, json={})
                await watching.until(f"{AX1}.manual_jog_minus_w", lambda held: held is False)
        finally:
            renewing.cancel()

        monitor_csrf = await _open_session(monitor, url, WebRole.MONITOR)
        async with monitor.get(url + f"/ws/jog?csrf={monitor_csrf}") as response:
            assert response.status == 403
            assert "role monitor may not jog continuously" in (await response.json())["error"]


async def test_handwheel_and_homing(web: WebProcess) -> None:
    async with browser_session() as http:
        csrf = await _open_session(http, web.url)
        live = await _live(http, web.url, [f"{AX1}.command_position_acs",
                                           f"{AX1}.homing_referenced_r", "ch1.ax2.homing_referenced_r"])
        await live.until(f"{AX1}.homing_referenced_r", lambda r: r is False)
        status, body = await json_request(http, "POST", web.url + "/api/channel/1/handwheel", csrf,
                                   json={"axis": 1, "pulses": 25, "resolution_mm": 0.01})
        assert (status, body) == (200, {"ok": True})
        await live.until(f"{AX1}.command_position_acs", lambda p: p == 2_500)  # 0.25 mm
        status, body = await json_request(http, "POST", web.url + "/api/channel/1/handwheel", csrf,
                                   json={"axis": 1, "pulses": 5, "resolution_mm": float("nan")})
        assert status == 400 and "finite" in body["error"]
        status, body = await json_request(http, "POST", web.url + "/api/channel/1/home", csrf,
                                   json={"axes": [1, 2]})
        assert (status, body) == (200, {"ok": True})
        await live.until(f"{AX1}.homing_referenced_r", bool)
        await live.until("ch1.ax2.homing_referenced_r", bool)
        status, body = await json_request(http, "POST", web.url + "/api/channel/1/home", csrf,
                                   json={"axes": ["X"]})
        assert status == 400


async def test_tool_list_read_and_written_with_the_services_roles(
        signed_web: WebProcess) -> None:
    url = signed_web.url
    async with browser_session() as operator, browser_session() as monitor:
        csrf = await _open_session(operator, url, WebRole.OPERATOR)
        monitor_csrf = await _open_session(monitor, url, WebRole.MONITOR)
        status, listed = await json_request(monitor, "GET", url + "/api/channel/1/tools")
        assert status == 200 and len(listed["rows"]) >= 8
        row = {"radius_mm": 2.5, "length_mm": 42.125}
        status, body = await json_request(monitor, "POST", url + "/api/channel/1/tools/7",
                                   monitor_csrf, json=row)
        assert status == 403 and body["error"] == (
            "ADS 0x704 INVALIDACCESS: role monitor may not write the tool list row wz[7] of "
            "channel 1; operator or admin may")
        status, body = await json_request(operator, "POST", url + "/api/channel/1/tools/7", csrf, json=row)
        assert (status, body) == (200, {"ok": True})
        _, listed = await json_request(monitor, "GET", url + "/api/channel/1/tools")
        assert listed["rows"][6] == {"d": 7, "valid": True, "radius_mm": 2.5, "length_mm": 42.125}
        # refused values change nothing: the service's words for a negative radius
        status, body = await json_request(operator, "POST", url + "/api/channel/1/tools/7", csrf,
                                   json={"radius_mm": -1.0})
        assert status == 400 and body["error"].startswith("ADS 0x706")
        status, body = await json_request(operator, "POST", url + "/api/channel/1/tools/7", csrf,
                                   json={"radius_mm": float("inf")})  # sent as Infinity
        assert status == 400 and "finite" in body["error"]
        _, listed = await json_request(monitor, "GET", url + "/api/channel/1/tools")
        assert listed["rows"][6]["radius_mm"] == 2.5


async def test_zero_offsets_read_and_written(signed_web: WebProcess) -> None:
    url = signed_web.url
    async with browser_session() as operator, browser_session() as monitor:
        csrf = await _open_session(operator, url, WebRole.OPERATOR)
        monitor_csrf = await _open_session(monitor, url, WebRole.MONITOR)
        status, table = await json_request(monitor, "GET", url + "/api/channel/1/offsets")
        assert status == 200 and table["axes"] == ["X", "Y", "Z"] and table["active"] == 0
        assert table["rows"][0]["name"] == "G54" and table["rows"][0]["offsets_mm"] == [0, 0, 0]
        change = {"offsets_mm": {"1": 12.5, "3": -3.25}}
        status, body = await json_request(monitor, "POST", url + "/api/channel/1/offsets/1",
                                   monitor_csrf, json=change)
        assert status == 403 and "role monitor may not write zero offset group 1" in body["error"]
        status, body = await json_request(operator, "POST", url + "/api/channel/1/offsets/1", csrf,
                                   json=change)
        assert (status, body) == (200, {"ok": True})
        _, table = await json_request(monitor, "GET", url + "/api/channel/1/offsets")
        assert table["rows"][0]["offsets_mm"] == [12.5, 0, -3.25]
        status, body = await json_request(operator, "POST", url + "/api/channel/1/offsets/1", csrf,
                                   json={"offsets_mm": {"X": 1}})
        assert status == 400 and "axis index" in body["error"]


async def test_alarm_history_with_times_acknowledge_all_and_reset(web: WebProcess) -> None:
    async with browser_session() as http:
        csrf = await _open_session(http, web.url)
        status, _ = await json_request(http, "POST", web.url + "/api/channel/1/mdi", csrf,
                                json={"blocks": "G1 X1 F"})
        live = await _live(http, web.url, ["ch1.mc_active_state_r"])
        await live.until("ch1.mc_active_state_r", lambda s: s == 6)  # ERROR
        _, active = await json_request(http, "GET", web.url + "/api/alarms")
        assert active["alarms"] and active["alarms"][-1]["state"] == "active"
        assert active["alarms"][-1]["time"].endswith("Z")
        # a manual block now: refused, naming the page's Reset, not the command line's
        status, body = await json_request(http, "POST", web.url + "/api/channel/1/mdi", csrf,
                                   json={"blocks": "G1 X1 F100"})
        assert status == 409 and "(Reset, beside the MDI line)" in body["error"]
        assert "cnc reset" not in body["error"]
        status, body = await json_request(http, "POST", web.url + "/api/alarms/acknowledge-all", csrf,
                                   json={})
        assert (status, body) == (200, {"ok": True})
        _, active = await json_request(http, "GET", web.url + "/api/alarms")
        assert {a["state"] for a in active["alarms"]} == {"acknowledged"}
        status, _ = await json_request(http, "POST", web.url + "/api/channel/1/reset", csrf, json={})
        assert status == 200
        await live.until("ch1.mc_active_state_r", lambda s: s != 6)
        _, active = await json_request(http, "GET", web.url + "/api/alarms")
        _, history = await json_request(http, "GET", web.url + "/api/alarms/history")
        assert active["alarms"] == []
        newest = history["alarms"][0]
        assert newest["state"] == "cleared" and newest["time"].endswith("Z")
        async with http.post(web.url + "/api/alarms/acknowledge-all") as response:
            assert response.status == 403  # no CSRF token


async def test_cnc_web_stops_at_once_with_pages_open_and_releases_a_held_jog(
        realtime_service: ServiceProcess) -> None:
    """Ctrl-C on cnc-web with a browser open: it closes the pages' WebSockets (1001) instead
    of waiting for them, and a jog key held through one is released on the way out."""
    from cnc_objects.clients import Client

    web = start_web(realtime_service.endpoint)
    try:
        async with browser_session() as http:
            csrf = await _open_session(http, web.url)
            live = await _live(http, web.url, [f"{AX1}.manual_jog_minus_w"])
            socket = await _jog_socket(http, web.url, csrf)
            await socket.send_json({"press": {"channel": 1, "axis": 1, "direction": -1}})
            await live.until(f"{AX1}.manual_jog_minus_w", lambda held: held is True)
            asked = time.monotonic()
            exit_code = await asyncio.to_thread(web.stop)
            took_s = time.monotonic() - asked
            closed = await socket.receive(timeout=WAIT_S)
            while closed.type == aiohttp.WSMsgType.TEXT:  # what it said before it closed
                closed = await socket.receive(timeout=WAIT_S)
    finally:
        web.stop()
    assert exit_code == 0 and took_s < STOP_TIMEOUT_S / 2, (exit_code, took_s)
    assert (closed.type, closed.data, closed.extra) == (
        aiohttp.WSMsgType.CLOSE, aiohttp.WSCloseCode.GOING_AWAY, "cnc-web is stopping")
    with Client(realtime_service.endpoint) as client:
        assert client.read(f"{AX1}.manual_jog_minus_w") is False
