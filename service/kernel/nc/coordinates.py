"""Machining coordinate systems (``#CS``): where a programmed point lies on the machine.

A coordinate system is an offset and a rotation relative to the coordinate system it
is selected in. ``#CS ON [x, y, z, a, b, c]`` selects one on top of those already
active (ISG links them: the offset and rotation of the new one refer to the previous
one), ``#CS OFF`` deselects the last one, ``#CS OFF ALL`` all. The angles a, b, c turn
about X, Y, Z in ISG's standard order: first c about Z, then b about the new Y', then a
about the newest X'' (``rotation.RotationOrder.ZYX``, intrinsic).

The active chain is kept as one ``Placement``: machine point = origin + R @ programmed
point. Only the main axes X, Y, Z are transformed; other axes are programmed as they
are. The decoder keeps positions in machine coordinates (the ``Block`` contract) and
converts the programmed words of every block with this placement.
"""

from __future__ import annotations

from dataclasses import dataclass

from .cycles.rotation import (
    IDENTITY,
    Matrix,
    RotationOrder,
    Vector,
    apply,
    apply_transposed,
    multiply,
    rotation_from_angles,
)


@dataclass(frozen=True, slots=True)
class CoordinateSystem:
    """One selected ``#CS``: its origin and axes in the coordinate system below it."""

    offset_mm: Vector
    rotation: Matrix  # columns: its X, Y, Z axes in the coordinate system below
    name: str = ""

    @classmethod
    def from_values(cls, offset_mm: Vector, angles_deg: Vector, name: str = "") -> CoordinateSystem:
        """``#CS ON [x, y, z, a, b, c]``: ISG's standard order (Z, Y', X'')."""
        a, b, c = angles_deg
        return cls(offset_mm, rotation_from_angles(a, b, c, RotationOrder.ZYX, True), name)


@dataclass(frozen=True, slots=True)
class Placement:
    """The active chain as one transform: machine = origin + rotation @ programmed."""

    origin_mm: Vector = (0.0, 0.0, 0.0)
    rotation: Matrix = IDENTITY

    def to_machine(self, p: Vector) -> Vector:
        """Machine coordinates of the programmed point ``p``."""
        x, y, z = apply(self.rotation, p)
        ox, oy, oz = self.origin_mm
        return (ox + x, oy + y, oz + z)

    def from_machine(self, m: Vector) -> Vector:
        """Programmed (machining) coordinates of the machine point ``m``."""
        ox, oy, oz = self.origin_mm
        return apply_transposed(self.rotation, (m[0] - ox, m[1] - oy, m[2] - oz))

    def then(self, cs: CoordinateSystem) -> Placement:
        """This placement with ``cs`` selected on top of it."""
        return Placement(self.to_machine(cs.offset_mm), multiply(self.rotation, cs.rotation))


def placement_of(stack: tuple[CoordinateSystem, ...]) -> Placement | None:
    """The placement of the selected chain (None when none is selected)."""
    if not stack:
        return None
    placement = Placement()
    for cs in stack:
        placement = placement.then(cs)
    return placement
