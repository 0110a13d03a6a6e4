"""What the objects of an axis show of manual mode: ``ManualAxisView`` (immutable, one
per axis in ``Channel.manual``, replaced by ``ManualMode.publish``) and the values of
ISG's ``hb_display_r.state``."""

from __future__ import annotations

from dataclasses import dataclass
from enum import IntEnum

from cnc_objects.protocol.units import UM01_PER_MM
from cnc_objects.protocol.values import ManualOperationMode


class DisplayState(IntEnum):
    """``hb_display_r.state``: whether the axis is assigned to a control element."""

    DEACTIVATED = 0  # manual mode is not active for the axis
    ENABLED = 1  # enabled, not assigned to a control element (no operation mode)
    ASSIGNED = 2  # enabled and assigned to a control element (an operation mode)


@dataclass(frozen=True, slots=True)
class ManualAxisView:
    """What the objects of one axis show (``hb_display_r`` and the project's objects)."""

    state: int = DisplayState.DEACTIVATED  # hb_display_r.state
    operation_mode: int = ManualOperationMode.NONE  # hb_display_r.operation_mode
    control_element: int = 0  # hb_display_r.control_element: 1 while assigned (one per axis)
    hr_aufloesung: int = 10  # handwheel path per pulse (0.1 um)
    tipp_geschw_um_s: int = 0  # continuous jog speed in effect (um/s)
    increment_01um: int = UM01_PER_MM  # jog increment: 1 mm
    rapid: bool = False  # the rapid key: jog at the rapid jog speed
    handwheel_counter: int = 0  # the counter as the PLC/HMI wrote it last
    jog_plus: bool = False  # the + key as written last
    jog_minus: bool = False  # the - key as written last
    velocity_um_s: float = 0.0  # velocity of the manual motion (um/s, signed)
    moving: bool = False  # a manual motion (jog, handwheel, homing) is under way
    limit_warning: bool = False  # the last manual motion stopped at a software limit
    referenced: bool = False  # the axis has been homed
    homing_active: bool = False  # the homing run of the axis is under way
    offset_01um: int = 0  # manual offset summed by G200/G201 in the running program (0.1 um)
