"""Catalog rows of the technology output (M/S/T to the PLC) and the spindle.

HLI symbols on port 851 under ``gpCh[i]`` (ISG: ``techno_unit_std_sync[..]``,
``used_units_std_sync_r``; the spindle's elements are ISG's ``gpAx[spindle]`` names,
placed under the channel because the twin's spindle has no HLI axis slot) and the same
values as COM objects of the channel (project offsets 0x3400..). Sources per object:
docs/spindle-plc.md. ``catalog`` turns the rows into templates (its TEMPLATES end with them).
"""

from __future__ import annotations

from enum import IntEnum
from typing import NamedTuple

from cnc_objects.protocol.constants import CncPort
from cnc_objects.protocol.datatypes import BOOLEAN, REAL64, SGN32, UNS16, UNS32, DataType
from cnc_objects.protocol.values import SpindleMode

from .addressing import GroupBase
from .model import Access
from .templates import PLC_GROUP, CatalogSizes, ObjectTemplate, Scope

R, RW = Access.READ, Access.READ_WRITE

TECHNO_UNITS = 16  # techno_unit_std_sync[0..15]: the units the PLC side lists
TECHNO_UNIT_OFFSET, TECHNO_UNIT_STRIDE = 0xD00, 0x10  # in the gpCh[i] block (project)
USED_UNITS_OFFSET = 0xE00
SPINDLE_OFFSET = 0xE10
COM_TECHNO, COM_SPINDLE = 0x3400, 0x3480  # channel COM offsets (project)

# (element below techno_unit_std_sync[k], offset, type, access, unit, text)
TECHNO_UNIT_FIELDS = (
    ("attribut_r.typ", 0x0, UNS16, R, "-", "1 M, 2 H, 3 S, 4 T function; 0 unit unused"),
    ("attribut_r.nr", 0x4, UNS32, R, "-",
     "M/T number, S in rpm (HLI_M_H_PROZESS.nr, HLI_T_PROZESS.id)"),
    ("attribut_r.synch", 0x8, UNS16, R, "-",
     "Synchronisation kind: 1 MOS, 2 MVS_SVS, 4 MVS_SNS, 8 MNS_SNS"),
    ("state_r", 0xA, BOOLEAN, R, "-", "TRUE: output and waiting for the PLC's acknowledge"),
    ("command_w", 0xB, BOOLEAN, RW, "-",
     "The PLC writes TRUE to acknowledge; reads TRUE once acknowledged"),
)

# (element below spindle, offset, type, access, unit, text)
SPINDLE_FIELDS = (
    ("mode_r", 0x0, UNS16, R, "-",
     "1 M05, 2 M03, 4 M04, 8 M19, 16 PLCOPEN, 32 RPF (ipo_state.spindle.mode_r)"),
    ("override_w", 0x2, UNS16, RW, "0.1 %", "Spindle override 0..1500 (ipo_mc_control.override)"),
    ("cmd_rev_r", 0x4, SGN32, R, "0.001 deg/s",
     "Commanded speed: S x override, signed (+ M3, - M4) (lr_state.cmd_rev_r)"),
    ("active_rev_r", 0x8, SGN32, R, "0.001 deg/s",
     "Actual speed after the ramp, signed (lr_state.active_rev_r)"),
    ("prog_rev_r", 0xC, SGN32, R, "0.001 deg/s", "Programmed S (project)"),
    ("speed_reached_r", 0x10, BOOLEAN, R, "-",
     "The spindle has done the last function: speed reached, stopped, oriented (project)"),
    ("position_r", 0x18, REAL64, R, "deg", "Spindle position after M19 (S.POS, project)"),
)

#: the enumeration fields of the spindle and their value sets (protocol.values)
SPINDLE_VALUES: dict[str, type[IntEnum]] = {"mode_r": SpindleMode}


class TechnologyRow(NamedTuple):
    """One object: an HLI symbol under gpCh[i] (``hli``) or a COM object of the channel."""

    element: str
    hli: bool
    offset: int
    dtype: DataType
    access: Access
    unit: str
    description: str
    values: type[IntEnum] | None = None  # value set of an enumeration object


def com_name(k: int, name: str) -> str:
    """COM element of field ``name`` of unit ``k``: mc_techno_<k>_<short name>."""
    short = name.replace("attribut_r.", "").removesuffix("_r").removesuffix("_w")
    return f"mc_techno_{k}_{short}"


TECHNOLOGY_ROWS: tuple[TechnologyRow, ...] = (
    *(
        TechnologyRow(
            f"techno_unit_std_sync[{k}].{name}", True,
            TECHNO_UNIT_OFFSET + k * TECHNO_UNIT_STRIDE + offset, dtype, access, unit,
            f"Technology unit {k}: {text}",
        )
        for k in range(TECHNO_UNITS)
        for name, offset, dtype, access, unit, text in TECHNO_UNIT_FIELDS
    ),
    TechnologyRow(
        "used_units_std_sync_r", True, USED_UNITS_OFFSET, UNS16, R, "-",
        "Technology units waiting for the PLC's acknowledge",
    ),
    *(
        TechnologyRow(f"spindle.{name}", True, SPINDLE_OFFSET + offset, dtype, access, unit,
                      text, SPINDLE_VALUES.get(name))
        for name, offset, dtype, access, unit, text in SPINDLE_FIELDS
    ),
    # the same values on the CNC ports (COM, per channel)
    *(
        TechnologyRow(
            com_name(k, name), False, COM_TECHNO + k * 8 + n, dtype, access, unit,
            f"Technology unit {k} (gpCh[i].techno_unit_std_sync[{k}].{name}): {text}",
        )
        for k in range(TECHNO_UNITS)
        for n, (name, _offset, dtype, access, unit, text) in enumerate(TECHNO_UNIT_FIELDS)
    ),
    *(
        TechnologyRow(f"mc_spindle_{name}", False, COM_SPINDLE + n, dtype, access, unit,
                      f"{text} (gpCh[i].spindle.{name})", SPINDLE_VALUES.get(name))
        for n, (name, _offset, dtype, access, unit, text) in enumerate(SPINDLE_FIELDS)
    ),
)


def technology_templates(sizes: CatalogSizes) -> tuple[ObjectTemplate, ...]:
    """The templates of the rows: HLI symbols of gpCh[i] and COM objects of the channel."""
    return tuple(
        ObjectTemplate(r.element, Scope.PLC_CHANNEL if r.hli else Scope.CHANNEL,
                       CncPort.PLC if r.hli else CncPort.COM,
                       PLC_GROUP if r.hli else GroupBase.COM_CHANNEL, r.offset, r.dtype,
                       r.access, r.unit, r.description, r.values)
        for r in TECHNOLOGY_ROWS
    )
