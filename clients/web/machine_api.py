"""The machine functions of cnc-web's API beyond the channel commands of ``api.py``:
continuous jog (``jog_hold.py``), handwheel, homing, the tool list and the zero offset
table, the alarm history and acknowledge-all.

Every write needs ``require_write``, as the service asks the same role of the same
object writes (``protocol/roles.py``: monitor reads; tool data, offsets, jog and homing
are object writes: operator). Lengths travel in mm and are converted by the scale the
service gives for each object (``clients/units.py``), as ``cnc tool`` and ``cnc
offsets`` do (docs/tools-offsets.md).
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

from aiohttp import web

from cnc_objects.clients.client import AsyncClient
from cnc_objects.clients.units import raw_value

from .. import names
from . import alarms, jog_hold
from .access import refusal, require_write
from .api import CLIENT_KEY, _body, _channel, _service_call

HANDWHEEL = 1  # ManualOperationMode: handwheel
MAX_PULSES = 100_000  # one handwheel request turns at most this many pulses
_INT32 = 2**32


def _client(request: web.Request) -> AsyncClient:
    return request.app[CLIENT_KEY]


def _whole(data: dict[str, Any], name: str, low: int, high: int) -> int:
    value = data.get(name)
    if not isinstance(value, int) or isinstance(value, bool) or not low <= value <= high:
        raise refusal(400, f"'{name}' must be a whole number in {low}..{high}")
    return value


def _mm(data: dict[str, Any], name: str) -> float | None:
    """The length ``name`` in mm, None when not given; NaN, infinities and text refused."""
    value = data.get(name)
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise refusal(400, f"'{name}' must be a finite number of mm")
    return float(value)


def _index(request: web.Request, part: str) -> int:
    text = request.match_info[part]
    if not text.isdigit() or int(text) < 1:
        raise refusal(400, f"{part} {text!r}: a whole number from 1")
    return int(text)


async def _manual(client: AsyncClient, channel: int) -> None:
    """Select MANUAL unless the channel is in it (the kernel refuses while it works)."""
    if await client.read(names.ch(channel).mc_active_mode_r) != jog_hold.MANUAL_MODE:
        await client.write(names.ch(channel).mc_command_mode_w, jog_hold.MANUAL_MODE)


async def _mm_per_raw(client: AsyncClient, name: str) -> float:
    """The object's scale: mm per raw unit (tool data and offsets are in 0.1 um)."""
    scale = (await client.describe(name)).scale
    return 1.0 if scale is None else scale.factor


async def _write_mm(client: AsyncClient, name: str, value_mm: float) -> None:
    await client.write(name, raw_value(await client.describe(name), value_mm))


# ---------------------------------------------------------------- manual mode

async def jog_socket(request: web.Request) -> web.StreamResponse:
    """``/ws/jog``: continuous jog held while the page renews it (``jog_hold``)."""
    return await jog_hold.jog_socket(request, _client(request))


@_service_call
async def handwheel(request: web.Request) -> web.StreamResponse:
    """Turn the handwheel of ``axis`` by ``pulses`` (signed), optionally at a new
    ``resolution_mm`` per pulse: the axis moves pulses x resolution, in MANUAL."""
    channel = _channel(request)
    data = await _body(request)
    axis = _whole(data, "axis", 1, 32)
    pulses = _whole(data, "pulses", -MAX_PULSES, MAX_PULSES)
    resolution_mm = _mm(data, "resolution_mm")
    require_write(request, f"turn the handwheel in channel {channel}")
    c, prefix = _client(request), f"ch{channel}.ax{axis}"
    await _manual(c, channel)
    await c.write(f"{prefix}.manual_operation_mode_w", HANDWHEEL)
    if resolution_mm is not None:
        await _write_mm(c, f"{prefix}.manual_hr_aufloesung_w", resolution_mm)
    counter = await c.read(f"{prefix}.manual_handwheel_counter_w")
    # a 32-bit counter: the kernel takes a wrap-around as the small step it is
    await c.write(f"{prefix}.manual_handwheel_counter_w",
                  (counter + pulses + 2**31) % _INT32 - 2**31)
    return web.json_response({"ok": True})


@_service_call
async def home(request: web.Request) -> web.StreamResponse:
    """Home the axes ``axes`` (indices from 1) in MANUAL; ``homing_referenced_r`` tells
    when each is referenced."""
    channel = _channel(request)
    axes = (await _body(request)).get("axes")
    if not isinstance(axes, list) or not axes or not all(
            isinstance(a, int) and not isinstance(a, bool) and 1 <= a <= 32 for a in axes):
        raise refusal(400, "'axes' must be a list of axis indices from 1")
    require_write(request, f"home axes in channel {channel}")
    c = _client(request)
    await _manual(c, channel)
    for axis in axes:
        await c.write(names.ch(channel).ax(axis).homing_start_w, True)
    return web.json_response({"ok": True})


# ---------------------------------------------------------------- tools and offsets

@_service_call
async def tools(request: web.Request) -> web.StreamResponse:
    """The tool list ``wz[1..n]`` of the channel (mm) and the active tool."""
    channel = _channel(request)
    c, ch = _client(request), f"ch{channel}"
    size = await c.read(f"{ch}.mc_tool_list_size_r")
    fields = ("valid", "radius", "laenge")
    names = [f"{ch}.wz[{d}].{f}" for d in range(1, size + 1) for f in fields]
    active = [f"{ch}.{n}" for n in ("mc_selected_tool_r", "mc_active_tool_r",
                                    "mc_active_tool_offset_r")]
    v = await c.read_many(names + active)
    mm_of = await _mm_per_raw(c, f"{ch}.wz[1].radius") if size else 1.0
    rows = [{"d": d, "valid": v[f"{ch}.wz[{d}].valid"],
             "radius_mm": round(v[f"{ch}.wz[{d}].radius"] * mm_of, 7),
             "length_mm": round(v[f"{ch}.wz[{d}].laenge"] * mm_of, 7)}
            for d in range(1, size + 1)]
    return web.json_response({"channel": channel, "selected_tool": v[active[0]],
                              "active_tool": v[active[1]], "d": v[active[2]], "rows": rows})


@_service_call
async def tool_set(request: web.Request) -> web.StreamResponse:
    """Write row ``d`` of the tool list: ``radius_mm``, ``length_mm`` (each optional) and
    ``valid`` (default TRUE: a row written holds a tool)."""
    channel, d = _channel(request), _index(request, "d")
    data = await _body(request)
    radius_mm, length_mm = _mm(data, "radius_mm"), _mm(data, "length_mm")
    valid = data.get("valid", True)
    if not isinstance(valid, bool):
        raise refusal(400, "'valid' must be true or false")
    require_write(request, f"write the tool list row wz[{d}] of channel {channel}")
    c, row = _client(request), f"ch{channel}.wz[{d}]"
    if radius_mm is not None:
        await _write_mm(c, f"{row}.radius", radius_mm)
    if length_mm is not None:
        await _write_mm(c, f"{row}.laenge", length_mm)
    await c.write(f"{row}.valid", valid)
    return web.json_response({"ok": True})


@_service_call
async def offsets(request: web.Request) -> web.StreamResponse:
    """The zero offset table ``np_grp[1..n-1]`` of the channel per axis (mm) and the
    group in effect (0 = G53)."""
    channel = _channel(request)
    c, ch = _client(request), f"ch{channel}"
    groups = await c.read(f"{ch}.mc_zero_offset_groups_r")
    axes = await c.browse(f"{ch}.ax*.axis_name")
    names = [o.name for o in axes]
    count = len(names)
    table = [f"{ch}.ax{a}.np_grp[{g}].v" for g in range(1, groups) for a in range(1, count + 1)]
    v = await c.read_many([*names, f"{ch}.mc_active_zero_offset_r", *table])
    mm_of = await _mm_per_raw(c, table[0]) if table else 1.0
    rows = [{"group": g, "name": f"G{53 + g}" if g <= 6 else f"G159={g}",
             "offsets_mm": [round(v[f"{ch}.ax{a}.np_grp[{g}].v"] * mm_of, 7)
                            for a in range(1, count + 1)]}
            for g in range(1, groups)]
    return web.json_response({"channel": channel, "axes": [v[n] for n in names],
                              "active": v[f"{ch}.mc_active_zero_offset_r"], "rows": rows})


@_service_call
async def offset_set(request: web.Request) -> web.StreamResponse:
    """Write the offsets of group ``group`` (1 = G54 ...): ``offsets_mm`` maps axis
    indices (from 1, as text) to mm."""
    channel, group = _channel(request), _index(request, "group")
    given = (await _body(request)).get("offsets_mm")
    if not isinstance(given, dict) or not given:
        raise refusal(400, "'offsets_mm' must map axis indices to mm: {\"1\": 10.5}")
    values: dict[int, float] = {}
    for axis in given:
        if not str(axis).isdigit() or int(axis) < 1:
            raise refusal(400, f"axis {axis!r}: an axis index from 1")
        mm = _mm(given, axis)
        if mm is None:
            raise refusal(400, f"axis {axis}: give its offset in mm")
        values[int(axis)] = mm
    require_write(request, f"write zero offset group {group} of channel {channel}")
    c = _client(request)
    for axis, value_mm in values.items():
        await _write_mm(c, f"ch{channel}.ax{axis}.np_grp[{group}].v", value_mm)
    return web.json_response({"ok": True})


# ---------------------------------------------------------------- alarms

@_service_call
async def alarm_history(request: web.Request) -> web.StreamResponse:
    """The last alarms raised, newest first, with their state now."""
    listed = await alarms.read_history(_client(request))
    return web.json_response({"alarms": [dataclasses.asdict(a) for a in listed]})


@_service_call
async def alarm_acknowledge_all(request: web.Request) -> web.StreamResponse:
    """Acknowledge every active alarm."""
    require_write(request, "acknowledge all alarms")
    await alarms.acknowledge_all(_client(request))
    return web.json_response({"ok": True})


def add_routes(app: web.Application) -> None:
    """This module's routes (next to ``api.add_routes``)."""
    get, post = web.get, web.post
    app.add_routes([
        get("/ws/jog", jog_socket),
        post(r"/api/channel/{channel}/handwheel", handwheel),
        post(r"/api/channel/{channel}/home", home),
        get(r"/api/channel/{channel}/tools", tools),
        post(r"/api/channel/{channel}/tools/{d}", tool_set),
        get(r"/api/channel/{channel}/offsets", offsets),
        post(r"/api/channel/{channel}/offsets/{group}", offset_set),
        get("/api/alarms/history", alarm_history),
        post("/api/alarms/acknowledge-all", alarm_acknowledge_all),
    ])
