"""How values are shown: units converted at the boundary, names for the enumerations."""

from __future__ import annotations

from cnc_objects.clients.channel_ops import CONTOUR_BLOCK_TYPES, MODES, STATES
from cnc_objects.clients.errors import AdsConnectionError, AdsError, AdsTimeoutError
from cnc_objects.protocol.units import UM01_PER_MM
from cnc_objects.protocol.values import LinkState

PERMILLE_PER_PERCENT = 10  # override travels in 0.1 %
# ch<c>.ax<a>.link_state; 1 is also what a suspended channel's axes read
LINK_STATES = {int(s): s.name.lower().replace("_", " ") for s in LinkState}


def mm(value_01um: float) -> str:
    """A position or length in 0.1 um as mm with 4 decimals (0.1 um resolution)."""
    return f"{value_01um / UM01_PER_MM:.4f}"


def mm_shown(value_mm: float) -> str:
    """A position or length already in mm (a feed in engineering units), 4 decimals."""
    return f"{value_mm:.4f}"


def mm_min_shown(value_mm_min: float) -> str:
    """A path speed already in mm/min, to 1 mm/min."""
    return f"{value_mm_min:.0f}"


def percent_shown(value_pct: float) -> str:
    """An override already in %."""
    return f"{value_pct:.1f} %"


def percent(value_01pct: int) -> str:
    """An override in 0.1 % as percent."""
    return f"{value_01pct / PERMILLE_PER_PERCENT:.1f} %"


def mode(value: int) -> str:
    """Operation mode name (``mc_active_mode_r``)."""
    return MODES.get(value, str(value))


def state(value: int) -> str:
    """Channel state name (``mc_active_state_r``)."""
    return STATES.get(value, str(value))


def link(state_value: int, drive: int) -> str:
    """Link state of a channel axis, with the drive it holds (``actual_link``)."""
    name = f"{state_value} {LINK_STATES.get(state_value, '?')}"
    return f"{name} → ax{drive}" if drive else name


def block_type(value: int) -> str:
    """Contour look-ahead element type (``block_type``)."""
    return CONTOUR_BLOCK_TYPES.get(value, str(value))


def on_off(value: bool) -> str:
    """A BOOLEAN as on/off."""
    return "on" if value else "off"


def unreachable(endpoint: str) -> str:
    """The line shown while the service does not answer."""
    return f"service at {endpoint} not reachable — retrying"


def refused(what: str, exc: AdsError, endpoint: str) -> str:
    """The line shown when a command failed: the ADS code in hex and the service's text;
    a missing reply says that the service is not reachable instead."""
    if isinstance(exc, (AdsTimeoutError, AdsConnectionError)):
        return f"{what}: no reply — {unreachable(endpoint)} ({exc})"
    return f"{what} refused: {exc}"  # "ADS 0x707 NOTREADY: channel 1 is ..."
