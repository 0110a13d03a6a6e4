"""Binds the technology-output and spindle objects (objects.catalog_technology).

Reads come from the channel's snapshot (``plc_functions``, ``spindle``); the PLC's
acknowledge and the spindle override become kernel commands.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from cnc_objects.objects import CncObject
from cnc_objects.objects.catalog_technology import (
    SPINDLE_FIELDS,
    TECHNO_UNIT_FIELDS,
    TECHNO_UNITS,
    com_name,
)

from .binding_types import AreaBinding, Binder, Getter, WriteBinder
from .kernel.commands import Command
from .kernel.commands_technology import AcknowledgeTechnoUnit, SetSpindleOverride
from .kernel.kernel import Kernel
from .kernel.plc_functions import TechnoUnit
from .kernel.spindle import SpindleState

RPM_TO_MDEG_S = 6000.0  # 1 rpm = 6000 x 0.001 degrees/s

_UNIT_VALUE: dict[str, Callable[[TechnoUnit], Any]] = {
    "attribut_r.typ": lambda u: int(u.type),
    "attribut_r.nr": lambda u: u.number,
    "attribut_r.synch": lambda u: int(u.sync),
    "state_r": lambda u: u.pending,
    "command_w": lambda u: u.acknowledged,
}
_UNUSED = {"attribut_r.typ": 0, "attribut_r.nr": 0, "attribut_r.synch": 0,
           "state_r": False, "command_w": False}

_SPINDLE_VALUE: dict[str, Callable[[SpindleState], Any]] = {
    "mode_r": lambda s: int(s.mode),
    "override_w": lambda s: s.override,
    "cmd_rev_r": lambda s: round(s.commanded_rpm * RPM_TO_MDEG_S),
    "active_rev_r": lambda s: round(s.actual_rpm * RPM_TO_MDEG_S),
    "prog_rev_r": lambda s: round(s.programmed_rpm * RPM_TO_MDEG_S),
    "speed_reached_r": lambda s: s.reached,
    "position_r": lambda s: s.position_deg,
}


def _unit(k: int, field: str) -> Callable[[Kernel, CncObject], Getter]:
    value = _UNIT_VALUE[field]

    def bind(kernel: Kernel, obj: CncObject) -> Getter:
        ci = kernel.channel_index(obj.channel)

        def get() -> Any:
            units = kernel.snapshot.channels[ci].plc_functions.units
            return value(units[k]) if k < len(units) else _UNUSED[field]

        return get

    return bind


def _spindle(field: str) -> Callable[[Kernel, CncObject], Getter]:
    value = _SPINDLE_VALUE[field]

    def bind(kernel: Kernel, obj: CncObject) -> Getter:
        ci = kernel.channel_index(obj.channel)
        return lambda: value(kernel.snapshot.channels[ci].spindle)

    return bind


def _used_units(kernel: Kernel, obj: CncObject) -> Getter:
    ci = kernel.channel_index(obj.channel)
    return lambda: kernel.snapshot.channels[ci].plc_functions.used_units


def _acknowledge(k: int) -> Callable[[Kernel, CncObject], Callable[[Any], Command]]:
    def bind(kernel: Kernel, obj: CncObject) -> Callable[[Any], Command]:
        ci = kernel.channel_index(obj.channel)
        return lambda value: AcknowledgeTechnoUnit(ci, k, bool(value))

    return bind


def _override(kernel: Kernel, obj: CncObject) -> Callable[[Any], Command]:
    ci = kernel.channel_index(obj.channel)
    return lambda value: SetSpindleOverride(ci, int(value))


TECHNOLOGY_READERS: dict[str, Binder] = {
    **{f"techno_unit_std_sync[{k}].{f[0]}": _unit(k, f[0])
       for k in range(TECHNO_UNITS) for f in TECHNO_UNIT_FIELDS},
    **{com_name(k, f[0]): _unit(k, f[0]) for k in range(TECHNO_UNITS) for f in TECHNO_UNIT_FIELDS},
    "used_units_std_sync_r": _used_units,
    **{f"spindle.{f[0]}": _spindle(f[0]) for f in SPINDLE_FIELDS},
    **{f"mc_spindle_{f[0]}": _spindle(f[0]) for f in SPINDLE_FIELDS},
}

TECHNOLOGY_WRITERS: dict[str, WriteBinder] = {
    **{f"techno_unit_std_sync[{k}].command_w": _acknowledge(k) for k in range(TECHNO_UNITS)},
    **{com_name(k, "command_w"): _acknowledge(k) for k in range(TECHNO_UNITS)},
    "spindle.override_w": _override,
    "mc_spindle_override_w": _override,
}


#: technology output and spindle (``objects.catalog_technology``)
BINDING = AreaBinding(lambda sizes: TECHNOLOGY_READERS, lambda sizes: TECHNOLOGY_WRITERS)
