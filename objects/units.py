"""Engineering units: how people read an object's value, derived from its unit column.

The objects carry the units of the ISG interfaces (positions in 0.1 um, path speeds in
um/s, overrides in 0.1 %); people read mm, mm/min and %. Each catalog unit maps to one
``EngineeringScale``: the unit people read, the factor (engineering value = raw value x
factor) and the decimals of the object's resolution in that unit (0.1 um = 4 decimals of
a mm). Units people already read (mm, mm/s, s) keep factor 1 and get their resolution, so
that clients can round away float noise. The scale goes out with browse
(``CncObject.describe``), so that no client hard-codes a factor.
"""

from __future__ import annotations

from dataclasses import dataclass

from cnc_objects.protocol.units import UM01_PER_MM


@dataclass(frozen=True, slots=True)
class EngineeringScale:
    """``raw x factor`` is the value in ``unit``; ``decimals`` is the resolution there."""

    unit: str
    factor: float
    decimals: int

    def describe(self) -> list[object]:
        """The browse field: ``[unit, factor, decimals]``."""
        return [self.unit, self.factor, self.decimals]


# catalog unit -> scale. A unit not listed ("-", "byte", enumerations) has no scale: its
# value is shown as it is.
SCALES: dict[str, EngineeringScale] = {
    "0.1 um": EngineeringScale("mm", 1 / UM01_PER_MM, 4),  # positions, lengths, offsets, tool data
    "um/s": EngineeringScale("mm/min", 0.06, 3),  # path and jog speeds, as F is programmed
    "0.1 %": EngineeringScale("%", 0.1, 1),  # overrides
    "0.001 deg/s": EngineeringScale("rpm", 1 / 6000, 3),  # spindle speeds: 360 000 per rpm
    # units people read as they are: factor 1, their resolution
    "mm": EngineeringScale("mm", 1.0, 4),
    "mm/s": EngineeringScale("mm/s", 1.0, 3),
    "mm/s^2": EngineeringScale("mm/s^2", 1.0, 3),
    "%": EngineeringScale("%", 1.0, 2),
    "s": EngineeringScale("s", 1.0, 6),  # kernel and program time: 1 us
    "deg": EngineeringScale("deg", 1.0, 4),
    "rad": EngineeringScale("rad", 1.0, 6),
    "us": EngineeringScale("us", 1.0, 0),
}


def scale_of(unit: str) -> EngineeringScale | None:
    """The engineering scale of a catalog unit; None for a unit without one."""
    return SCALES.get(unit)
