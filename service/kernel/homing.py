"""Homing (ISG's reference run, G74 or by object): the referenced state of an axis.

In this twin the drives have ideal encoders, so homing is one motion: the axis travels
at its homing speed (``ManualAxisConfig.homing_vel_mm_s``) under its acceleration to its
reference position (P-AXIS-00152 ``pos_refpkt``) and is referenced there. ISG starts it
by the homing mode or by ``G74`` in a program or manual block; ``G74 Z1 X2 Y2`` homes
the axes in the order of the numbers, axes with the same number together
(``homing_groups``). A machine parameter (``programs_need_referenced_axes``) makes
program starts wait for it; the embedded default does not.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass


@dataclass(frozen=True, slots=True)
class HomingState:
    """Homing of one axis: done (``referenced``) or under way (``active``)."""

    referenced: bool = False
    active: bool = False


def homing_groups(order: Iterable[tuple[int, int]]) -> list[tuple[int, ...]]:
    """``(axis_index, sequence number)`` pairs of a G74 block as the groups that home
    together, in ascending sequence number: ``G74 Z1 X2 Y2`` -> ``[(Z,), (X, Y)]``."""
    by_number: dict[int, list[int]] = {}
    for axis_index, number in order:
        by_number.setdefault(number, []).append(axis_index)
    return [tuple(by_number[n]) for n in sorted(by_number)]
