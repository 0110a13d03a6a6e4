"""``G200`` / ``G201`` / ``G202``: ISG's manual mode inside an NC program.

(IS/tf5200_programming_manual/206639371.html, 206633483.html)

* ``G200 [X.. Y..]`` (this block only): manual mode *without* parallel interpolation.
  The program stops at the block; the named axes (all of the channel's when none is
  named) can be jogged or moved by handwheel; START ("continue motion") goes on with the
  program, and manual mode ends for every axis.
* ``G201 X.. [Y..]`` (modal): manual mode *with* parallel interpolation: the named axes
  can be jogged while the path runs, until ``G202``.
* ``G202 [X..]`` (modal, the initial state): manual mode off for the named axes, or for
  all of them when none is named. Manual offsets summed up stay (ISG: "not cleared by
  G202").

The axis words of such a block name the axes; their values are not positions. One
block holds at most one of the three (ISG error 20129).
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

from .blocks import Block, ManualModeKind, ManualModeRequest
from .errors import NcErrorId


def manual_mode_request(number: int, axis_words: list[tuple[int, float, int, str]],
                        g_pos: int, axis_count: int, err: Any) -> ManualModeRequest:
    """The request of a G200/G201/G202 block; ``err(id, text, pos)`` makes the NcError
    of a bad block (raised here)."""
    kind = ManualModeKind(number)
    axes: list[int] = []
    for axis, _value, pos, letter in axis_words:
        if axis < 0:
            raise err(NcErrorId.UNKNOWN_WORD, f"{letter} is not an axis of this channel", pos)
        if axis not in axes:
            axes.append(axis)
    if not axes:
        if kind == ManualModeKind.G201:
            raise err(NcErrorId.MANUAL_MODE_WITHOUT_AXES,
                      "G201 needs the axes to jog in parallel to the path: G201 X1 [Y1]", g_pos)
        axes = list(range(axis_count))
    return ManualModeRequest(kind, tuple(axes))


def with_manual_mode(block: Block, request: ManualModeRequest) -> Block:
    """``block`` carrying its G200/G201/G202 request."""
    return replace(block, manual_mode=request)
