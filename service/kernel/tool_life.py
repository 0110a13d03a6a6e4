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

from dataclasses import dataclass

from .kernel_state import KernelState
from .nc.blocks import Block, MotionKind
from .refusal import Refusal, RefusalReason
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


@dataclass(frozen=True, slots=True)
class SetToolLifeUsed:
    """Write ``wz[index].life_used`` (s): typically 0 after a regrind or a new tool."""

    channel_index: int
    index: int
    value_s: float
    cycle_s: float

    def apply(self, state: KernelState) -> Refusal | None:
        ch = state.channels[self.channel_index]
        size = ch.tooling.tools.size
        if not 1 <= self.index <= size:
            return Refusal(RefusalReason.INVALID_VALUE,
                           f"wz[{self.index}]: the tool list has the entries 1..{size}")
        if not 0.0 <= self.value_s <= 1e9:  # NaN fails too
            return Refusal(RefusalReason.INVALID_VALUE,
                           f"wz[{self.index}].life_used: {self.value_s:g} s is outside 0..1e9")
        used = dict(ch.tool_cut_cycles)
        used[self.index] = round(self.value_s / self.cycle_s)
        ch.tool_cut_cycles = used
        return None
