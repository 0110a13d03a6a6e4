"""The scale of lengths on the wire, written once.

ISG's interfaces carry positions, distances, offsets and tool data in 0.1 µm (the
"increments" of the HLI): an object's raw value divided by ``UM01_PER_MM`` is millimetres.
Every module that converts uses this constant; the unit suffix of such values in names is
``_01um`` (``command_position_01um``). How people read the other units (um/s as mm/min,
0.1 % as %) is ``objects.units``; the browse reply carries it to clients.
"""

from __future__ import annotations

from typing import Final

UM01_PER_MM: Final = 10_000
"""0.1 µm steps per millimetre: the scale of every length object."""
