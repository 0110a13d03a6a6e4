"""Tool life: the cutting time each tool has run (project; ISG leaves tool life to an
external tool management).

A tool cuts while it is in the spindle (``tool_active``, the T of the last M6) and a
feed block (G1/G2/G3, not G0) is the block in the interpolator, feedhold included. The
time is counted in cycles (an integer: stepping cycle by cycle and running cycles in
bulk give the same count) per tool number, in ``Channel.tool_cut_cycles``; the object
``wz[i].life_used`` shows it in seconds. The mapping is replaced, never changed in
place, so a snapshot may keep the old one.
"""

from __future__ import annotations

from .nc.blocks import Block, MotionKind
from .state import Channel


def count_cutting(ch: Channel, block: Block | None, cycles: int) -> None:
    """``cycles`` cycles of ``block`` in the interpolator: the active tool cut them when
    it is a feed block."""
    tool = ch.tooling.tool_active
    if not tool or block is None or block.motion is None or (
            block.motion.kind == MotionKind.RAPID):
        return
    used = dict(ch.tool_cut_cycles)
    used[tool] = used.get(tool, 0) + cycles
    ch.tool_cut_cycles = used


