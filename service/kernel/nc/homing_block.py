"""``G74``: the homing block of an NC program or manual block (ISG's reference run).

``G74 X1 Y1`` homes X and Y: the block moves them in a straight line from where they
are to their reference positions (P-AXIS-00152 ``pos_refpkt``) at the lowest homing
speed of the programmed axes, and at the block's end they are referenced
(``Block.homing_axes``; the channel runner marks them). The value of each axis word is
its place in ISG's homing sequence; this kernel homes the axes of one block together,
so all of them must carry the same number: ``G74 Z1`` then ``G74 X1 Y1`` is the
sequence ``G74 Z1 X2 Y2`` written as two blocks (error 20136 otherwise, naming it).
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

from .blocks import Block, Compensation, Motion, MotionKind
from .construct import make_motion
from .errors import NcErrorId
from .modal import ModalState

HOMING_DEFAULT_MM_S = 10.0  # homing speed of an axis the modal state has no entry for


def homing_motion(modal: ModalState, axis_words: list[tuple[int, float, int, str]],
                  g_pos: int, plane: tuple[int, int], err: Any,
                  ) -> tuple[Motion | None, tuple[int, ...]]:
    """The motion of a G74 block and the channel axis indices it homes; ``err(id, text,
    pos)`` makes the NcError of a bad block (raised here)."""
    if not axis_words:
        raise err(NcErrorId.INVALID_HOMING,
                  "G74 needs the axes to home, each with its place in the sequence: G74 X1 Y1",
                  g_pos)
    numbers = set()
    for axis, value, pos, letter in axis_words:
        if axis < 0:
            raise err(NcErrorId.UNKNOWN_WORD, f"{letter} is not an axis of this channel", pos)
        if not math.isfinite(value) or value != int(value) or value < 1:
            raise err(NcErrorId.INVALID_HOMING,
                      f"G74 {letter}{value:g}: the place in the homing sequence is a whole "
                      "number from 1", pos)
        numbers.add(int(value))
    if len(numbers) > 1:
        pos = axis_words[0][2]
        raise err(NcErrorId.INVALID_HOMING,
                  "this kernel homes the axes of one G74 block together: write one G74 block "
                  "per place in the sequence (G74 Z1, then G74 X1 Y1)", pos)
    start = modal.position_mm
    end = list(start)
    speeds = []
    axes = tuple(axis for axis, *_ in axis_words)
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


def with_homing(block: Block, axes: tuple[int, ...]) -> Block:
    """``block`` carrying the axes G74 references at its end."""
    return replace(block, homing_axes=axes)
