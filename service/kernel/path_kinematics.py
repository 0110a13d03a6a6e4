"""``#TRAFO ON`` in a run: the path runs in the programmed coordinates (the tool tip in
X, Y, Z and the rotary axes), and every cycle's position is turned into axis positions
by the channel's kinematics (``path.kinematics``) before it is output.

The axes' limits hold for the axis positions, not for the tip. At points along each
block (its end, and one more per degree its rotary axes turn, at most
``LIMIT_SAMPLES``): a block that would put an axis beyond its software limit is refused before the path
takes it, with ISG's software limit error (50100/50101) naming the axis; and the block's
feed is capped so that no axis exceeds its velocity (a linear axis far from a turning
table's centre moves faster than the tip). Between those points an axis can pass its
limit by the arc's sagitta at most; the axes' accelerations are the planner's, in the
programmed coordinates.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

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
    vel_max_mm_s: tuple[float, ...]  # the axes' velocity limits

    def axes_of(self, program_mm: Sequence[float], tool_length_mm: float) -> tuple[float, ...]:
        """The axis positions of a programmed position (RTCP)."""
        return self.chain.to_axes(program_mm, self.xyz, tool_length_mm)

    def program_of(self, axes_mm: Sequence[float], tool_length_mm: float) -> tuple[float, ...]:
        """The programmed position of the axis positions."""
        return self.chain.to_program(axes_mm, self.xyz, tool_length_mm)

    def prepared(self, block: Block) -> Block | tuple[int, str]:
        """``block`` (decoded under ``#TRAFO ON``) as the path takes it: its feed capped
        so that no axis exceeds its velocity (the tip's feed would drive a linear axis
        far from a turning table's centre faster than the tip), or ISG's error (50100
        below, 50101 above the limit) and why it would put an axis beyond its software
        limit. Both are judged at points along the block: its end and one per degree
        its rotary axes turn (at most ``LIMIT_SAMPLES``); with the rotary axes fixed the
        axes move linearly, and the end alone tells."""
        motion, trafo = block.motion, block.trafo
        if motion is None or trafo is None:
            return block
        start, end = motion.start_mm, motion.end_mm
        turn_deg = max(abs(end[a.axis_index] - start[a.axis_index])
                       for a in self.chain.rotators)
        samples = min(LIMIT_SAMPLES, 1 + int(turn_deg))
        monitored = self._monitored
        xyz = self.xyz
        before_p: Sequence[float] = start
        before_q = self.axes_of(start, trafo.tool_length_mm)
        ratio = [0.0] * len(start)  # the most an axis moves per mm of path
        for k in range(1, samples + 1):
            t = k / samples
            point = [a + (b - a) * t for a, b in zip(start, end, strict=True)]
            axes = self.axes_of(point, trafo.tool_length_mm)
            if monitored:
                for name, value, (low, high) in zip(self.names, axes, self.sw_limits_mm,
                                                    strict=True):
                    if not low <= value <= high:
                        error = (PathErrorId.SW_LIMIT_MIN if value < low
                                 else PathErrorId.SW_LIMIT_MAX)
                        return int(error), (f"#TRAFO ON: axis {name} would reach "
                                            f"{value:.4f}, beyond its software limit "
                                            f"[{low:g}, {high:g}]")
            path = math.dist([point[i] for i in xyz], [before_p[i] for i in xyz])
            if path == 0.0:  # the rotary axes alone: the path runs along them
                path = math.dist(point, before_p)
            if path > 0.0:
                for i, (q, q0) in enumerate(zip(axes, before_q, strict=True)):
                    ratio[i] = max(ratio[i], abs(q - q0) / path)
            before_p, before_q = point, axes
        cap = min((v / r for v, r in zip(self.vel_max_mm_s, ratio, strict=True) if r > 0.0),
                  default=math.inf)
        if cap < motion.feed_mm_s:
            return replace(block, motion=replace(motion, feed_mm_s=cap))
        return block

    @property
    def _monitored(self) -> bool:
        return any(math.isfinite(low) or math.isfinite(high) for low, high in self.sw_limits_mm)
