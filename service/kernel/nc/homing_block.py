"""``G74``: the homing block of an NC program or manual block (ISG's reference run).

``G74 X1 Y1`` homes X and Y: the block moves them in a straight line from where they
are to their reference positions (P-AXIS-00152 ``pos_refpkt``) at the lowest homing
speed of the programmed axes, and at the block's end they are referenced
(``Block.homing_axes``; the channel runner marks them). The value of each axis word is
its place in ISG's homing sequence, axes with the same value home together:
``G74 X2 Y3 Z1`` homes Z, then X, then Y (issue 39). Each place is one homing step, a
block of the same source; the steps after the first ride on the first block
(``Block.then``) and the decoder yields them right after it, so the path stops after
each group and the next starts from there. Errors: 20136 for G74 without axes (an axis
twice is the parser's 20111, as in any block), 20816 (ISG: "coordinate for homing is
out of data format") for a place that is not a whole number from 1.
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

from ..homing import homing_groups
from .blocks import Block, Compensation, Motion, MotionKind
from .construct import make_motion
from .errors import NcErrorId
from .modal import ModalState

HOMING_DEFAULT_MM_S = 10.0  # homing speed of an axis the modal state has no entry for


HomingStep = tuple[Motion | None, tuple[int, ...]]  # the motion and the axes it homes


def homing_steps(modal: ModalState, axis_words: list[tuple[int, float, int, str]],
                 g_pos: int, plane: tuple[int, int], err: Any) -> list[HomingStep]:
    """The homing steps of a G74 block in the order of their places (at least one);
    ``err(id, text, pos)`` makes the NcError of a bad block (raised here). The modal
    position ends at the last step's end."""
    if not axis_words:
        raise err(NcErrorId.INVALID_HOMING,
                  "G74 needs the axes to home, each with its place in the sequence: G74 X1 Y1",
                  g_pos)
    places: dict[int, int] = {}
    for axis, value, pos, letter in axis_words:
        if axis < 0:
            raise err(NcErrorId.UNKNOWN_WORD, f"{letter} is not an axis of this channel", pos)
        if not math.isfinite(value) or value != int(value) or value < 1:
            raise err(NcErrorId.HOMING_PLACE_OUT_OF_RANGE,
                      f"G74 {letter}{value:g}: the place in the homing sequence is a whole "
                      "number from 1", pos)
        places[axis] = int(value)
    return [_step(modal, axes, plane) for axes in homing_groups(places.items())]


def _step(modal: ModalState, axes: tuple[int, ...], plane: tuple[int, int]) -> HomingStep:
    """One group of a G74 sequence: the straight move of ``axes`` to their reference
    positions at the lowest homing speed among them."""
    start = modal.position_mm
    end = list(start)
    speeds = []
    for axis in axes:
        ref_mm, vel_mm_s = modal.homing.get(axis, (0.0, HOMING_DEFAULT_MM_S))
        end[axis] = ref_mm
        speeds.append(vel_mm_s)
    end_t = tuple(end)
    modal.position_mm = end_t
    if end_t == start:
        return None, axes
    return make_motion(MotionKind.LINEAR, start, end_t, min(speeds), plane, None,
                       Compensation.OFF, 0.0), axes


def with_homing(block: Block, steps: list[HomingStep]) -> Block:
    """``block`` as the first step of a G74 sequence: it homes the first group, the
    later groups follow as blocks of the same source (``Block.then``), each without the
    block's M/H/S/T output, which happens once, with the first step."""
    later = tuple(replace(block, motion=motion, homing_axes=axes, m_functions=(),
                          h_functions=(), spindle_speed_rpm=None, tool=None,
                          spindle_pos_deg=None, manual_mode=None, dwell_s=0.0)
                  for motion, axes in steps[1:])
    return replace(block, homing_axes=steps[0][1], then=later)
