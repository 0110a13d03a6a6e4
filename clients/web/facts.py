"""The facts the browser's pages need, from their one source (``GET /api/facts``).

The pages show positions in mm, feeds in mm/min, overrides in %, spindle modes as M3/M5
and channel states by name. None of that is typed again in JavaScript: the scale of
lengths is ``protocol.units``, the value sets are ``protocol.values`` (and the look-ahead
block names of ``clients.channel_ops``, as the terminal HMI and ``cnc lookahead`` show
them), the engineering unit of each channel and axis object is its catalog unit's scale
(``objects.units``). The page's core module loads this once at start.
"""

from __future__ import annotations

import re
from enum import IntEnum
from typing import Any

from aiohttp import web

from cnc_objects.clients.channel_ops import CONTOUR_BLOCK_TYPES, MODES, STATES
from cnc_objects.objects.catalog import Scope, templates
from cnc_objects.objects.units import scale_of
from cnc_objects.protocol.units import UM01_PER_MM
from cnc_objects.protocol.values import WORKING_STATES, LinkState, SpindleMode

# Objects the pages address by their leaf (``ch1.mc_active_feedrate_r`` ->
# ``mc_active_feedrate_r``): one per channel or per axis of a channel.
_LEAF_SCOPES = frozenset({Scope.CHANNEL, Scope.CHANNEL_AXIS})


def _spoken(member: IntEnum) -> str:
    """A value's name as people read it: ``WAITING_ACK`` -> ``waiting ack``."""
    return member.name.lower().replace("_", " ")


def _m_function(member: SpindleMode) -> str:
    """A spindle mode as its M function is written: ``M05`` -> ``M5``; others by name."""
    return re.sub(r"^M0*(\d)", r"M\1", member.name)


def _table(values: dict[int, str]) -> dict[str, str]:
    """JSON keys are strings: ``{"3": "READY"}``."""
    return {str(k): v for k, v in values.items()}


def leaf_scales() -> dict[str, dict[str, Any]]:
    """``{leaf: {unit, factor, decimals}}`` of every channel and axis object whose
    catalog unit has an engineering scale (``mc_active_feedrate_r``: mm/min, 0.06)."""
    scales: dict[str, dict[str, Any]] = {}
    for template in templates():  # every area's fixed objects (no table rows)
        scale = scale_of(template.unit)
        if template.scope not in _LEAF_SCOPES or scale is None:
            continue
        shown = {"unit": scale.unit, "factor": scale.factor, "decimals": scale.decimals}
        if scales.setdefault(template.element, shown) != shown:
            raise ValueError(f"{template.element}: two units in the catalog")
    return scales


def facts() -> dict[str, Any]:
    """What ``GET /api/facts`` answers (the same for every session)."""
    return {
        "um01_per_mm": UM01_PER_MM,
        "modes": _table(MODES),
        "states": _table(STATES),
        "working_states": [s.name for s in sorted(WORKING_STATES)],
        "spindle_modes": _table({int(m): _m_function(m) for m in SpindleMode}),
        "link_states": _table({int(s): _spoken(s) for s in LinkState}),
        "contour_types": _table(CONTOUR_BLOCK_TYPES),
        "scales": leaf_scales(),
    }


async def get_facts(request: web.Request) -> web.StreamResponse:
    """The facts, built once per application."""
    return web.json_response(request.app[FACTS_KEY])


FACTS_KEY = web.AppKey("facts", dict[str, Any])


def add_routes(app: web.Application) -> None:
    """``GET /api/facts``."""
    app[FACTS_KEY] = facts()
    app.router.add_get("/api/facts", get_facts)
