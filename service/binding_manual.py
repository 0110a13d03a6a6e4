"""Binds the manual-mode and homing objects (objects/catalog_manual.py) to the kernel.

Reads come from the snapshot's ``Channel.manual`` (one ``ManualAxisView`` per axis);
writes become ``ManualAxisCommand``s for the channel's ``ManualMode``.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from cnc_objects.objects import CncObject

from .binding_types import AreaBinding, Binder, Getter, WriteBinder
from .kernel.commands_manual import ManualAxisCommand
from .kernel.kernel import Kernel


def _view(attr: str, wrap: Callable[[Any], Any] = lambda v: v
          ) -> Callable[[Kernel, CncObject], Getter]:
    """A field of the axis's ``ManualAxisView`` in the last snapshot."""

    def bind(kernel: Kernel, obj: CncObject) -> Getter:
        ci, ai = kernel.channel_index(obj.channel), obj.axis - 1
        return lambda: wrap(getattr(kernel.snapshot.channels[ci].manual[ai], attr))

    return bind


def _write(action: str) -> Callable[[Kernel, CncObject], Callable[[Any], ManualAxisCommand]]:
    def bind(kernel: Kernel, obj: CncObject) -> Callable[[Any], ManualAxisCommand]:
        ci, ai = kernel.channel_index(obj.channel), obj.axis - 1
        return lambda value: ManualAxisCommand(ci, ai, action, value)

    return bind


def _int32(value: float) -> int:
    return max(-0x8000_0000, min(0x7FFF_FFFF, round(value)))


MANUAL_READERS: dict[str, Binder] = {
    "hb_display_r.state": _view("state"),
    "hb_display_r.operation_mode": _view("operation_mode"),
    "hb_display_r.control_element": _view("control_element"),
    "hb_display_r.hr_aufloesung": _view("hr_aufloesung"),
    "hb_display_r.tipp_geschw": _view("tipp_geschw_um_s", _int32),
    "manual_operation_mode_w": _view("operation_mode"),
    "manual_jog_plus_w": _view("jog_plus"),
    "manual_jog_minus_w": _view("jog_minus"),
    "manual_rapid_w": _view("rapid"),
    "manual_increment_w": _view("increment_01um"),
    "manual_handwheel_counter_w": _view("handwheel_counter"),
    "manual_hr_aufloesung_w": _view("hr_aufloesung"),
    "manual_velocity_r": _view("velocity_um_s"),
    "manual_moving_r": _view("moving"),
    "manual_limit_warning_r": _view("limit_warning"),
    "homing_referenced_r": _view("referenced"),
    "homing_active_r": _view("homing_active"),
    "manual_offset_r": _view("offset_01um", _int32),
}

MANUAL_WRITERS: dict[str, WriteBinder] = {
    "manual_operation_mode_w": _write("operation_mode"),
    "manual_jog_plus_w": _write("jog_plus"),
    "manual_jog_minus_w": _write("jog_minus"),
    "manual_rapid_w": _write("rapid"),
    "manual_increment_w": _write("increment"),
    "manual_handwheel_counter_w": _write("handwheel"),
    "manual_hr_aufloesung_w": _write("resolution"),
    "homing_start_w": _write("homing_start"),
}


#: manual mode and homing (``objects.catalog_manual``)
BINDING = AreaBinding(lambda sizes: MANUAL_READERS, lambda sizes: MANUAL_WRITERS)
