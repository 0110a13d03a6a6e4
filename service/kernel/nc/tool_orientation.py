"""Turning the tool onto a coordinate system's Z axis with the rotary axes (``#TRAFO
ON`` on a five-axis channel): the NC line SysPosRotationToPlane (@P1 = 1, 2) and a
call pattern's tilted ``#AT`` positions write.

The direction is given in the coordinates before the selection; an active ``#CS`` turns
it into the decoder's (the tip) coordinates first. Of the kinematics' two solutions the
one nearer ``near_deg`` is taken (``Kinematics.orientation_to_rotary``); the tip stays
where it is (RTCP).
"""

from __future__ import annotations

from ..path.kinematics import Kinematics
from .cycles.rotation import Matrix, Vector, apply
from .literals import nc_number
from .modal import ModalState


def normal_of(rotation: Matrix, modal: ModalState) -> Vector:
    """The Z axis of ``rotation`` (selected on top of the active ``#CS``) in the
    decoder's coordinates."""
    normal = (rotation[0][2], rotation[1][2], rotation[2][2])
    placement = modal.cs_placement
    return normal if placement is None else apply(placement.rotation, normal)


def turn_line(chain: Kinematics, axes: tuple[str, ...], normal: Vector,
              near_deg: dict[int, float]) -> tuple[str, dict[int, float]]:
    """The ``G90 G00`` line of the rotary axes that turns the tool onto ``normal``, and
    their values (raises ``KinematicsError`` when the rotary axes cannot)."""
    rotary = chain.orientation_to_rotary(normal, near_deg)
    words = " ".join(f"{axes[k]}{nc_number(v)}" for k, v in sorted(rotary.items()))
    return f"G90 G00 {words}", rotary


def rotary_of(chain: Kinematics, modal: ModalState) -> dict[int, float]:
    """The rotary axes' programmed positions (the decoder's modal state)."""
    return {a.axis_index: modal.position_mm[a.axis_index] for a in chain.rotators}
