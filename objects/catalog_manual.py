"""Objects of manual mode and homing (docs/manual.md lists each with its ISG source).

Templates (``templates.ObjectTemplate``), one area of ``catalog.AREAS``. Per axis of a
channel:

- ``hb_display_r.*``: ISG's status of manual mode, an HLI symbol on port 851
  (``gpCh[i].bahn_state.coord_r[k].hb_display_r.state`` ...);
- ``manual_*``: the project's objects through which an HMI or PLC jogs the axis
  (operation mode, keys, rapid key, increment, handwheel counter and resolution) and
  reads the manual motion back (COM, channel axis objects, project offsets 0x33xx);
- ``homing_*``: start homing by object, referenced state.
"""

from __future__ import annotations

from cnc_objects.protocol.constants import CncPort
from cnc_objects.protocol.datatypes import BOOLEAN, REAL64, SGN32, UNS16, UNS32
from cnc_objects.protocol.values import ManualOperationMode

from .addressing import GroupBase
from .model import Access
from .templates import PLC_GROUP, CatalogSizes, ObjectTemplate, Scope

R, W, RW = Access.READ, Access.WRITE, Access.READ_WRITE
_AXIS, _HLI = Scope.CHANNEL_AXIS, Scope.PLC_CHANNEL_AXIS
COM, PLC = CncPort.COM, CncPort.PLC
COM_CH = GroupBase.COM_CHANNEL

_MODES = "0 none, 1 handwheel, 2 continuous jog, 3 jog by increments"

MANUAL_ROWS: tuple[ObjectTemplate, ...] = (
    # --- HLI status of manual mode: gpCh[i].bahn_state.coord_r[k].hb_display_r --------
    ObjectTemplate("hb_display_r.state", _HLI, PLC, PLC_GROUP, 0x0, UNS16, R, "-",
              "State of manual mode for the axis: 0 deactivated, 1 enabled without a control "
              "element, 2 enabled and assigned to a control element (an operation mode)"),
    ObjectTemplate("hb_display_r.operation_mode", _HLI, PLC, PLC_GROUP, 0x2, UNS16, R, "-",
              f"Operation mode of manual mode: {_MODES}", ManualOperationMode),
    ObjectTemplate("hb_display_r.control_element", _HLI, PLC, PLC_GROUP, 0x4, UNS16, R, "-",
              "Logical number of the control element linked to the axis; 0 = none "
              "(this kernel: 1 while an operation mode is selected)"),
    ObjectTemplate("hb_display_r.hr_aufloesung", _HLI, PLC, PLC_GROUP, 0x6, SGN32, R, "0.1 um",
              "Handwheel resolution: path per handwheel pulse"),
    ObjectTemplate("hb_display_r.tipp_geschw", _HLI, PLC, PLC_GROUP, 0xA, SGN32, R, "um/s",
              "Velocity of the axis in continuous jog mode (rapid key and feed override "
              "applied)"),
    # --- manual mode by object (project) -------------------------------------------------
    ObjectTemplate("manual_operation_mode_w", _AXIS, COM, COM_CH, 0x3300, UNS16, RW, "-",
              f"Select the axis's operation mode in manual mode: {_MODES}; at standstill "
              "(project)", ManualOperationMode),
    ObjectTemplate("manual_jog_plus_w", _AXIS, COM, COM_CH, 0x3301, BOOLEAN, RW, "-",
              "Jog key +: TRUE pressed, FALSE released. Continuous jog moves while pressed; "
              "jog by increments moves one increment per press (project)"),
    ObjectTemplate("manual_jog_minus_w", _AXIS, COM, COM_CH, 0x3302, BOOLEAN, RW, "-",
              "Jog key -: as manual_jog_plus_w, in the negative direction (project)"),
    ObjectTemplate("manual_rapid_w", _AXIS, COM, COM_CH, 0x3303, BOOLEAN, RW, "-",
              "Rapid key: TRUE jogs at the rapid jog speed (jog_rapid_vel_mm_s) (project)"),
    ObjectTemplate("manual_increment_w", _AXIS, COM, COM_CH, 0x3304, UNS32, RW, "0.1 um",
              "Jog increment: 1 (0.1 um) .. 100000 (10 mm); others are refused (project)"),
    ObjectTemplate("manual_handwheel_counter_w", _AXIS, COM, COM_CH, 0x3305, SGN32, RW, "pulses",
              "Handwheel counter the PLC or HMI writes; in handwheel mode the axis moves by "
              "(new - old) x hr_aufloesung; 32-bit wrap-around is a small step (project)"),
    ObjectTemplate("manual_hr_aufloesung_w", _AXIS, COM, COM_CH, 0x3306, SGN32, RW, "0.1 um",
              "Handwheel resolution: path per pulse, 1 .. 100000 (project)"),
    ObjectTemplate("manual_velocity_r", _AXIS, COM, COM_CH, 0x3307, REAL64, R, "um/s",
              "Velocity of the axis's manual motion (signed; 0 at standstill) (project)"),
    ObjectTemplate("manual_moving_r", _AXIS, COM, COM_CH, 0x3308, BOOLEAN, R, "-",
              "TRUE while a manual motion (jog, handwheel, homing) of the axis is under way "
              "(project)"),
    ObjectTemplate("manual_limit_warning_r", _AXIS, COM, COM_CH, 0x3309, BOOLEAN, R, "-",
              "TRUE: the axis's last manual motion stopped at a software limit (warning "
              "70910 is listed); the next motion away or RESET clears it (project)"),
    ObjectTemplate("homing_start_w", _AXIS, COM, COM_CH, 0x3310, BOOLEAN, W, "-",
              "Write TRUE in MANUAL: home the axis (to P-AXIS-00152 pos_refpkt at "
              "homing_vel_mm_s) (project)"),
    ObjectTemplate("homing_referenced_r", _AXIS, COM, COM_CH, 0x3311, BOOLEAN, R, "-",
              "TRUE once the axis is homed (G74 or homing_start_w) (project)"),
    ObjectTemplate("homing_active_r", _AXIS, COM, COM_CH, 0x3312, BOOLEAN, R, "-",
              "TRUE while the axis's homing run is under way (project)"),
    ObjectTemplate("manual_offset_r", _AXIS, COM, COM_CH, 0x3313, SGN32, R, "0.1 um",
              "Manual offset summed by G200/G201 jogs in the running program, added to the "
              "path's output; 0 again when the program ends (project)"),
)


def manual_templates(sizes: CatalogSizes) -> tuple[ObjectTemplate, ...]:
    """The templates of manual mode and homing (one per row)."""
    return MANUAL_ROWS
