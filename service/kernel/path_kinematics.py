"""``#TRAFO ON`` in a run: the path runs in the programmed coordinates (the tool tip in
X, Y, Z and the rotary axes), and every cycle's position is turned into axis positions
by the channel's kinematics (``path.kinematics``) before it is output.

The axes' software limits hold for the axis positions, not for the tip: a block whose
end, or a point along it (one per degree its rotary axes turn, at most
``LIMIT_SAMPLES``), would put an axis beyond its limit is refused before the path takes
it, with ISG's software limit error (50100/50101) naming the axis. Between those points
an axis can pass its limit by the arc's sagitta at most.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from .nc.blocks import Block
from .path.errors import PathErrorId
from .path.kinematics import Kinematics

LIMIT_SAMPLES = 16  # points along a block checked against the axes' software limits


@dataclass(frozen=True, slots=True)
class PathKinematics:
    """The channel's kinematics as a run applies it."""

    chain: Kinematics
    xyz: tuple[int, int, int]  # the channel axes that hold the tool tip
    sw_limits_mm: tuple[tuple[float, float], ...]  # the axes' monitored limits
    names: tuple[str, ...]  # the channel's axis names, for the error texts

    def axes_of(self, program_mm: Sequence[float], tool_length_mm: float) -> tuple[float, ...]:
        """The axis positions of a programmed position (RTCP)."""
        return self.chain.to_axes(program_mm, self.xyz, tool_length_mm)

    def program_of(self, axes_mm: Sequence[float], tool_length_mm: float) -> tuple[float, ...]:
        """The programmed position of the axis positions."""
        return self.chain.to_program(axes_mm, self.xyz, tool_length_mm)

    def limit_error(self, block: Block) -> tuple[int, str] | None:
        """ISG's error (50100 below, 50101 above the limit) and why ``block`` (decoded
        under ``#TRAFO ON``) would put an axis beyond its software limit, or None.
        Checked at the block's end and at points along it, one per degree its rotary
        axes turn (at most ``LIMIT_SAMPLES``); nothing when no limit is monitored."""
        motion, trafo = block.motion, block.trafo
        if motion is None or trafo is None or not self._monitored:
            return None
        start, end = motion.start_mm, motion.end_mm
        turn_deg = max(abs(end[a.axis_index] - start[a.axis_index])
                       for a in self.chain.rotators)
        samples = min(LIMIT_SAMPLES, 1 + int(turn_deg))
        for k in range(1, samples + 1):
            t = k / samples
            point = [a + (b - a) * t for a, b in zip(start, end, strict=True)]
            axes = self.axes_of(point, trafo.tool_length_mm)
            for name, value, (low, high) in zip(self.names, axes, self.sw_limits_mm,
                                                strict=True):
                if not low <= value <= high:
                    error = PathErrorId.SW_LIMIT_MIN if value < low else PathErrorId.SW_LIMIT_MAX
                    return int(error), (f"#TRAFO ON: axis {name} would reach {value:.4f}, "
                                        f"beyond its software limit [{low:g}, {high:g}]")
        return None

    @property
    def _monitored(self) -> bool:
        return any(math.isfinite(low) or math.isfinite(high) for low, high in self.sw_limits_mm)
