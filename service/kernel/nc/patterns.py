"""Call patterns (ISG SysPosPattern): positions at which a cycle runs.

``#PATTERN BEGIN [ID=n]`` opens a definition, each ``#AT [x, y, z]`` or
``#AT [x, y, z, a, b, c]`` adds a position (only a rotation about Z, ``c``, is
permitted), ``#PATTERN END`` stores it under its id (replacing one of the same id).
Nothing but ``#AT`` may stand inside a definition. ``#PATTERN DELETE [ID=n]`` and
``#PATTERN DELETE ALL`` remove definitions. Definitions live until the program ends.

A cycle called with ``PATTERN_ID`` and ``PATTERN_RETRACT`` runs once per position
(``cycle_run``): rapid to the retraction plane Z = PATTERN_RETRACT, rapid to X/Y of the
position, then the position (X, Y, Z) and its rotation about Z become a machining
coordinate system (``#CS``) in which the cycle runs; after it the coordinate system is
deselected and the tool goes back to the retraction plane.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from .source import LogicalLine


@dataclass(frozen=True, slots=True)
class PatternPosition:
    """One ``#AT``: where the cycle runs and its rotations (a about X, b about Y, c about
    Z, as ``#CS ON`` takes them)."""

    x_mm: float
    y_mm: float
    z_mm: float
    c_deg: float = 0.0
    a_deg: float = 0.0
    b_deg: float = 0.0

    @property
    def tilted(self) -> bool:
        """A rotation about X or Y: the tool must turn with it."""
        return self.a_deg != 0.0 or self.b_deg != 0.0


@dataclass(slots=True)
class OpenPattern:
    """A definition between ``#PATTERN BEGIN`` and ``#PATTERN END``."""

    id: int
    line: LogicalLine  # the BEGIN line (for "not closed" errors)
    pos: int
    positions: list[PatternPosition] = field(default_factory=list)
