"""The HTTP API of cnc-web: JSON over the one ``AsyncClient`` of the server.

Reads need a session; writes need ``require_write`` (role and CSRF token). A refusal of
the service (``AdsError``) is answered 400 (409 for a channel that is not ready, 504 for
no reply) with its sentence as ``error``: the page shows the service's own words.
"""

from __future__ import annotations

import contextlib
import dataclasses
import math
from collections.abc import Awaitable, Callable
from typing import Any

from aiohttp import web

from cnc_objects.clients.channel_ops import MODES, STATES
from cnc_objects.clients.client import AsyncClient
from cnc_objects.clients.errors import AdsError, AdsTimeoutError, ClientValueError
from cnc_objects.clients.hmi.machine import discover
from cnc_objects.protocol.errors import AdsReturnCode
from cnc_objects.protocol.units import UM01_PER_MM
from cnc_objects.protocol.values import ChannelMode, ManualOperationMode

from .. import names
from . import alarms
from .access import ACCESS_KEY, STORE_ROLE, WRITE_ROLE, refusal, require_write, set_session_cookie
from .hub import json_value
from .signin import TooManyAttempts
from .users import WebRole

CLIENT_KEY: web.AppKey[AsyncClient] = web.AppKey("client")
MAX_UPLOAD_BYTES = 4 * 1024 * 1024  # a program larger than this is refused before it is read
TRACE_TIMEOUT_S = 60.0  # wall time for the dry run that draws a program's tool path
MAX_COUNT_DIGITS = 9  # a count in a query (``limit``): more digits than any catalogue needs

Handler = Callable[[web.Request], Awaitable[web.StreamResponse]]


def _client(request: web.Request) -> AsyncClient:
    return request.app[CLIENT_KEY]


def _service_call(handler: Handler) -> Handler:
    """Answer the service's refusals with their sentence (see the module docstring)."""

    async def wrapped(request: web.Request) -> web.StreamResponse:
        try:
            return await handler(request)
        except AdsTimeoutError as exc:
            raise refusal(504, str(exc)) from None
        except AdsError as exc:
            status = 409 if exc.code == AdsReturnCode.DEVICE_NOTREADY else 400
            raise refusal(status, str(exc)) from None
        except ClientValueError as exc:
            raise refusal(400, str(exc)) from None

    return wrapped


async def _body(request: web.Request) -> dict[str, Any]:
    try:
        data = await request.json()
    except ValueError:
        raise refusal(400, "the request body is not JSON") from None
    if not isinstance(data, dict):
        raise refusal(400, "the request body is not a JSON object")
    return data


def _field(data: dict[str, Any], name: str, kind: type) -> Any:
    value = data.get(name)
    if not isinstance(value, kind) or isinstance(value, bool) and kind is not bool:
        raise refusal(400, f"'{name}' is missing or not a {kind.__name__}")
    return value


def _finite(data: dict[str, Any], name: str, default: float) -> float:
    """The number ``name`` of a request body (``default`` when absent), refused 400 when
    it is not a finite number: NaN and infinities included, as JSON numbers or strings."""
    value = data.get(name, default)
    number = math.nan
    if isinstance(value, int | float) and not isinstance(value, bool):
        with contextlib.suppress(OverflowError):  # an integer beyond any float stays NaN
            number = float(value)
    if not math.isfinite(number):
        raise refusal(400, f"'{name}' is not a finite number: {str(value)[:40]}")
    return number


def _query_count(request: web.Request, name: str, default: int) -> int:
    """The whole number >= 0 of the query parameter ``name``, else 400."""
    text = request.query.get(name, str(default))
    if not (text.isascii() and text.isdigit() and len(text) <= MAX_COUNT_DIGITS):
        raise refusal(400, f"'{name}' is not a whole number >= 0: {text[:40]!r}")
    return int(text)


def _channel(request: web.Request) -> int:
    text = request.match_info["channel"]
    if not text.isdigit() or int(text) < 1:
        raise refusal(400, f"no channel {text!r}: channels are numbered from 1")
    return int(text)


# ---------------------------------------------------------------- session

async def get_session(request: web.Request) -> web.StreamResponse:
    """The browser's role, its CSRF token, what it may and whether it must sign in."""
    access = request.app[ACCESS_KEY]
    session, session_id = access.session_of(request), None
    if session is None and not access.sign_in_required:
        session, session_id = access.sessions.issue(access.open_role, None)
    users = access.users
    roles = [r.label for r in users.roles] if users is not None else [access.open_role.label]
    response = web.json_response({
        "role": session.role.label if session else None,
        "csrf": session.csrf if session else None,
        "may_write": bool(session and session.role.may(WRITE_ROLE)),
        "may_upload": bool(session and session.role.may(STORE_ROLE)),
        "sign_in_required": access.sign_in_required,
        "roles": roles,
        "endpoint": _client(request).endpoint,
    })
    if session_id is not None:
        set_session_cookie(response, session_id)
    return response


async def login(request: web.Request) -> web.StreamResponse:
    """Sign in as ``role`` with its ``password``: 400 for a malformed request, 429 (with
    ``Retry-After``) over the attempt limits of ``signin.py``, 401 for a wrong password;
    the hash is checked off the event loop."""
    access = request.app[ACCESS_KEY]
    data = await _body(request)
    users = access.users
    if users is None:
        raise refusal(400, "this server has no users file: everyone on this machine is "
                           f"{access.open_role.label} without signing in")
    try:
        role = WebRole.parse(_field(data, "role", str))
    except ValueError as exc:
        raise refusal(400, str(exc)) from None
    password = _field(data, "password", str)
    try:
        access.gate.admit(request.remote or "?", role.label)
    except TooManyAttempts as exc:
        raise refusal(429, str(exc), {"Retry-After": str(exc.retry_after_s)}) from None
    stored = users.hashes.get(role)
    if not await access.gate.check(lambda: users.verify(role, password)) or stored is None:
        raise refusal(401, f"wrong password for role {role.label}")
    response = web.json_response({"role": role.label})
    access.start_session(response, role, stored)
    return response


async def logout(request: web.Request) -> web.StreamResponse:
    """End the session: in the server (its cookie no longer opens anything), and the
    cookie is dropped."""
    response = web.json_response({"role": None})
    request.app[ACCESS_KEY].end_session(request, response)
    return response


# ---------------------------------------------------------------- machine and objects

@_service_call
async def machine(request: web.Request) -> web.StreamResponse:
    """Channels and axes (discovered, as cnc-hmi does), and the names of modes/states."""
    found = await discover(_client(request))
    return web.json_response({
        "channels": [
            {"id": c.id, "plc_index": c.plc_index,
             "axes": [{"index": a.index, "name": a.name, "drive": a.drive, "unit": a.unit}
                      for a in c.axes]}
            for c in found.channels
        ],
        "modes": {str(k): v for k, v in MODES.items()},
        "states": {str(k): v for k, v in STATES.items()},
    })


@_service_call
async def objects(request: web.Request) -> web.StreamResponse:
    """The objects whose names match ``pattern`` (glob; ``*`` for all), at most ``limit``."""
    pattern = request.query.get("pattern", "*") or "*"
    limit = _query_count(request, "limit", 500)
    found = await _client(request).browse(pattern)
    rows = [dataclasses.asdict(o) | {"enum": {str(k): v for k, v in o.enum.items()}}
            for o in found[:limit]]
    return web.json_response({"objects": rows, "total": len(found)})


@_service_call
async def read(request: web.Request) -> web.StreamResponse:
    """One object's value."""
    name = request.query.get("name", "")
    return web.json_response({"name": name, "value": json_value(await _client(request).read(name))})


@_service_call
async def write(request: web.Request) -> web.StreamResponse:
    """Write ``value`` to the object ``name``; with ``"units": true`` the value is in
    engineering units (mm, %, rpm: the object's scale), converted by the client."""
    data = await _body(request)
    name = _field(data, "name", str)
    units = data.get("units", False)
    if not isinstance(units, bool):
        raise refusal(400, "'units' is not a boolean")
    require_write(request, f"write {name}")
    await _client(request).write(name, data.get("value"), units=units)
    return web.json_response({"ok": True})


# ---------------------------------------------------------------- programs

@_service_call
async def programs(request: web.Request) -> web.StreamResponse:
    """The program store's files."""
    entries = await _client(request).programs()
    return web.json_response({"programs": [dataclasses.asdict(e) for e in entries]})


@_service_call
async def program_text(request: web.Request) -> web.StreamResponse:
    """A stored program's text."""
    data = await _client(request).download(request.match_info["name"])
    return web.json_response({"name": request.match_info["name"],
                              "text": data.decode("utf-8", errors="replace")})


@_service_call
async def upload(request: web.Request) -> web.StreamResponse:
    """Store the uploaded file (form field ``file``) under its file name."""
    require_write(request, "upload programs", STORE_ROLE)
    if request.content_length is not None and request.content_length > MAX_UPLOAD_BYTES:
        raise refusal(400, f"the upload is larger than {MAX_UPLOAD_BYTES} bytes")
    reader = await request.multipart()
    async for part in reader:
        if getattr(part, "name", None) == "file" and getattr(part, "filename", None):
            data = await part.read()  # type: ignore[union-attr]
            name = str(part.filename)  # type: ignore[union-attr]
            await _client(request).upload(name, bytes(data))
            return web.json_response({"name": name, "size_bytes": len(data)})
    raise refusal(400, "the upload has no file (form field 'file')")


# ---------------------------------------------------------------- channel commands

@_service_call
async def select(request: web.Request) -> web.StreamResponse:
    """Select ``program`` in the channel (AUTOMATIC), without starting it."""
    channel = _channel(request)
    program = _field(await _body(request), "program", str)
    require_write(request, f"select {program}")
    await _client(request).write(names.ch(channel).mc_command_program_name_w, program)
    return web.json_response({"ok": True})


def _command(what: str, call: Callable[[AsyncClient, int], Awaitable[Any]]) -> Handler:
    @_service_call
    async def handler(request: web.Request) -> web.StreamResponse:
        channel = _channel(request)
        require_write(request, f"{what} channel {channel}")
        await call(_client(request), channel)
        return web.json_response({"ok": True})

    return handler


start = _command("START", lambda c, ch: c.start(ch))
hold = _command("HOLD", lambda c, ch: c.hold(ch))
reset = _command("RESET", lambda c, ch: c.reset(ch))


@_service_call
async def mdi(request: web.Request) -> web.StreamResponse:
    """Run ``blocks`` as manual blocks."""
    channel = _channel(request)
    blocks = _field(await _body(request), "blocks", str)
    require_write(request, f"run manual blocks in channel {channel}")
    await _client(request).mdi(blocks, channel)
    return web.json_response({"ok": True})


@_service_call
async def jog(request: web.Request) -> web.StreamResponse:
    """Jog axis ``axis`` (index from 1) by ``increment_mm`` in ``direction`` (+1/-1), in
    MANUAL (selected when the channel is in another mode), as ``cnc jog`` does."""
    channel = _channel(request)
    data = await _body(request)
    axis = _field(data, "axis", int)
    direction = _field(data, "direction", int)
    increment_mm = _finite(data, "increment_mm", 1.0)
    require_write(request, f"jog in channel {channel}")
    c, prefix = _client(request), f"ch{channel}.ax{axis}"
    # every check before the first write: a refused jog leaves the channel's mode alone
    increment = await c.find(f"{prefix}.manual_increment_w")
    if increment is None:
        raise refusal(400, f"no axis {axis} in channel {channel}")
    increment_01um = round(increment_mm * UM01_PER_MM)
    low, high = increment.dtype.minimum, increment.dtype.maximum
    if low is not None and high is not None and not low <= increment_01um <= high:
        raise refusal(400, f"'increment_mm' {increment_mm} is out of range "
                           f"({low / UM01_PER_MM}..{high / UM01_PER_MM} mm)")
    if direction not in (1, -1):
        raise refusal(400, f"'direction' is +1 or -1, not {direction}")
    if await c.read(names.ch(channel).mc_active_mode_r) != ChannelMode.MANUAL:
        await c.write(names.ch(channel).mc_command_mode_w, ChannelMode.MANUAL)
    await c.write(f"{prefix}.manual_operation_mode_w", ManualOperationMode.INCREMENTAL)
    await c.write(f"{prefix}.manual_increment_w", increment_01um)
    key = f"{prefix}.manual_jog_{'plus' if direction > 0 else 'minus'}_w"
    await c.write(key, True)
    await c.write(key, False)
    return web.json_response({"ok": True})


@_service_call
async def check(request: web.Request) -> web.StreamResponse:
    """Syntax check of ``program``: every error with its line and column."""
    channel = _channel(request)
    program = _field(await _body(request), "program", str)
    require_write(request, f"check {program} (a syntax check runs in the channel)")
    result = await _client(request).syntax_check(program, channel)
    return web.json_response({
        "errors": [dataclasses.asdict(e) for e in result.errors],
        "aborted": dataclasses.asdict(result.aborted) if result.aborted else None,
        "lines": result.lines, "error_count": result.error_count,
    })


@_service_call
async def trace(request: web.Request) -> web.StreamResponse:
    """The tool path and the planned speed profile of ``program``: a dry run
    (PROD_TIME, no axis moves), thinned to at most ``MAX_TRACE_POINTS`` points. The last
    ``TRACES_KEPT`` answers are kept per channel, program and stored version, so that a
    page opened while the program runs (the channel busy) still gets its planned path;
    such an answer changes nothing and is given to every role. With ``"automatic":
    true`` (the page plans each program it shows) a dry run that ends in ERROR is
    followed by RESET: looking at a program with errors leaves the channel as it was."""
    channel = _channel(request)
    data = await _body(request)
    program = _field(data, "program", str)
    c = _client(request)
    stored = next((e for e in await c.programs() if e.name == program), None)
    key = (channel, program, stored.size_bytes, stored.mtime_s) if stored else None
    kept = request.app[TRACES_KEY]
    if key is not None and key in kept:
        return web.json_response(kept[key])
    require_write(request, f"dry-run {program} to draw its path")
    run = await c.trace_run(program, channel, timeout_s=TRACE_TIMEOUT_S)
    if data.get("automatic") is True and run.ended != "READY":
        await c.reset(channel)
    step = max(1, len(run.t_s) // MAX_TRACE_POINTS)
    answer = {
        "program": run.program, "ended": run.ended, "program_time_s": run.program_time_s,
        "positions_mm": {k: v[::step].round(4).tolist() for k, v in run.positions_mm.items()},
        "path_mm": run.path_mm[::step].round(4).tolist(),
        "v_mm_s": run.v_mm_s[::step].round(3).tolist(),
        "feed_limit_mm_s": run.feed_limit_mm_s[::step].round(3).tolist(),
        "line": run.line[::step].tolist(),
    }
    if key is not None:
        kept[key] = answer
        while len(kept) > TRACES_KEPT:
            del kept[next(iter(kept))]  # the oldest
    return web.json_response(answer)


MAX_TRACE_POINTS = 4000  # enough for a smooth drawing, small enough for a tablet
TRACES_KEPT = 16  # dry-run answers kept (each at most ~200 kB of JSON)
TRACES_KEY: web.AppKey[dict[tuple[int, str, int, float], dict[str, Any]]] = web.AppKey("traces")


@_service_call
async def lookahead(request: web.Request) -> web.StreamResponse:
    """The contour look-ahead's elements ahead of the channel (mode 2 from its path
    distance), through the PLC control unit (a request: needs the write role)."""
    channel = _channel(request)
    require_write(request, f"request the contour look-ahead of channel {channel}")
    c = _client(request)
    found = await discover(c)
    view = next((v for v in found.channels if v.id == channel), None)
    if view is None:
        raise refusal(404, f"no channel {channel}")
    marked = request.query.get("mode", "ahead") == "marked"
    start = 0.0 if marked else float(await c.read(view.obj("dist_prog_start")))
    reply = await c.contour_lookahead(start, 0.0 if marked else 1e9, plc_channel=view.plc_index)
    return web.json_response({
        "max_dist_prog_start": reply.max_dist_prog_start,
        "count_logged_blocks": reply.count_logged_blocks,
        "log_active": reply.log_active,
        "blocks": [dataclasses.asdict(b) for b in reply.blocks],
    })


@_service_call
async def alarm_list(request: web.Request) -> web.StreamResponse:
    """The active alarms, oldest first (``alarms.read_alarms``)."""
    listed = await alarms.read_alarms(_client(request))
    return web.json_response({"alarms": [dataclasses.asdict(a) for a in listed]})


@_service_call
async def alarm_acknowledge(request: web.Request) -> web.StreamResponse:
    """Acknowledge one alarm by its sequence number (``alarms.acknowledge``)."""
    try:
        sequence = int(request.match_info["sequence"])
    except ValueError:
        raise web.HTTPBadRequest(text="the alarm's sequence number is a whole number") from None
    require_write(request, f"acknowledge alarm {sequence}")
    await alarms.acknowledge(_client(request), sequence)
    return web.json_response({"ok": True})


def add_routes(app: web.Application) -> None:
    """The API's routes."""
    app[TRACES_KEY] = {}
    get, post = web.get, web.post
    app.add_routes([
        get("/api/session", get_session), post("/api/login", login), post("/api/logout", logout),
        get("/api/machine", machine), get("/api/objects", objects),
        get("/api/read", read), post("/api/write", write),
        get("/api/programs", programs), post("/api/programs", upload),
        get("/api/programs/{name}", program_text),
        post(r"/api/channel/{channel}/select", select),
        post(r"/api/channel/{channel}/start", start),
        post(r"/api/channel/{channel}/hold", hold),
        post(r"/api/channel/{channel}/reset", reset),
        post(r"/api/channel/{channel}/mdi", mdi),
        post(r"/api/channel/{channel}/jog", jog),
        post(r"/api/channel/{channel}/check", check),
        post(r"/api/channel/{channel}/trace", trace),
        get(r"/api/channel/{channel}/lookahead", lookahead),
        get("/api/alarms", alarm_list),
        post(r"/api/alarms/{sequence}/acknowledge", alarm_acknowledge),
    ])
