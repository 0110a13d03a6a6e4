"""Point-vector programming on a five-axis channel: ``#ORI MODE [VECTOR_2DOF]`` under
``#TRAFO ON`` makes A, B and C the components of the tool's direction.

ISG (programming manual, "Orientation programming", tf5200_programming_manual/528339979.html,
and "Programming and configuration of 5-axis kinematics (#ORI MODE)", 528345739.html):
the vector points from the tool tip towards the tool holder; "The address letters A, B, C
must always be used; they have no reference to configured axis names in the channel list.
The vector components need not be specified in standardised form." Example:
``X50 Y50 Z100 A-0.5 B0.5 C0.7071``.

A component left out of a block is 0 (a block with none of them keeps the orientation).
The direction is in the active ``#CS``'s coordinates, like X, Y and Z. Of the
kinematics' two solutions the one nearer the rotary axes' present values is taken
(``Kinematics.orientation_to_rotary``), and the block moves those axes to it, as if their
angles had been programmed.
"""

from __future__ import annotations

import math

from ..path.kinematics import Kinematics, KinematicsError
from .cycles.rotation import apply
from .errors import ErrorAt, NcErrorId
from .modal import DistanceMode, ModalState

# a block's axis words: (channel axis or -1, value, pos, letter), as blockexec collects them
AxisWords = list[tuple[int, float, int, str]]
_COMPONENT = {"A": 0, "B": 1, "C": 2}


def rotary_words(chain: Kinematics, axis_words: AxisWords, modal: ModalState,
                 axes: tuple[str, ...], shift: tuple[float, ...] | None, err: ErrorAt
                 ) -> AxisWords:
    """``axis_words`` with A, B, C (the direction) replaced by the words of the rotary
    axes that turn the tool to it, at the place of the first component; unchanged when
    the block has none. Errors: a zero vector 20113, a direction the rotary axes cannot
    reach 292004."""
    vector = [0.0, 0.0, 0.0]
    first_pos = -1
    kept: AxisWords = []
    for word in axis_words:
        k = _COMPONENT.get(word[3])
        if k is None:
            kept.append(word)
            continue
        vector[k] = word[1]
        first_pos = word[2] if first_pos < 0 else min(first_pos, word[2])
    if first_pos < 0:
        return axis_words
    if math.hypot(*vector) < 1e-12 or not all(math.isfinite(v) for v in vector):
        raise err(NcErrorId.VALUE_OUT_OF_RANGE,
                  f"the tool direction A{vector[0]:g} B{vector[1]:g} C{vector[2]:g} has no "
                  "length", first_pos)
    direction = (vector[0], vector[1], vector[2])
    placement = modal.cs_placement
    if placement is not None:
        direction = apply(placement.rotation, direction)
    start = modal.position_mm
    near = {a.axis_index: start[a.axis_index] for a in chain.rotators}
    try:
        rotary = chain.orientation_to_rotary(direction, near)
    except KinematicsError as exc:
        raise err(NcErrorId.TRAFO_POSE_UNREACHABLE,
                  f"the rotary axes cannot turn the tool to A{vector[0]:g} B{vector[1]:g} "
                  f"C{vector[2]:g}: {exc}", first_pos) from None
    incremental = modal.distance == DistanceMode.INCREMENTAL
    for axis, angle in sorted(rotary.items()):
        # the value that _motion turns back into ``angle`` (absolute: plus the zero offset)
        value = (angle - start[axis] if incremental
                 else angle - shift[axis] if shift is not None else angle)
        kept.append((axis, value, first_pos, axes[axis]))
    return kept
