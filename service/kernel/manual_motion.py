"""One axis moved by hand: a velocity profile under the axis's acceleration, cycle by cycle.

Manual mode (jog, increment, handwheel) and homing move single axes, not a path: each
axis follows its own goal with its own speed and acceleration. ``AxisMotion`` holds the
goal and the velocity of one axis and advances it by one cycle in ``step``.

The goal is a target position (incremental jog, handwheel, homing) or a direction
(continuous jog, which runs toward the software limit in that direction). Every cycle the
axis may change its velocity by at most ``acc * dt`` and never goes faster than it could
still stop at the goal: ``v <= sqrt(2 * acc * distance)`` (the braking distance
``v^2 / 2a``). The position never passes a software limit: a goal beyond it is cut at
the limit and ``hit_limit`` says so.

Units: ``_mm``, ``_mm_s``, ``_mm_s2``, ``_s`` as everywhere in the kernel.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

_STANDSTILL_MM_S = 1e-9  # below this the axis is at rest
_AT_GOAL_MM = 1e-9  # closer than this the goal is reached


@dataclass(frozen=True, slots=True)
class AxisDynamicsLimits:
    """What one manual motion may do: speed, acceleration, software limits."""

    vel_mm_s: float
    acc_mm_s2: float
    sw_limit_min_mm: float
    sw_limit_max_mm: float

    def clip(self, position_mm: float) -> float:
        """``position_mm`` inside the software limits."""
        return min(max(position_mm, self.sw_limit_min_mm), self.sw_limit_max_mm)


@dataclass(slots=True)
class AxisMotion:
    """The manual motion of one axis: a goal, the velocity, the limits in force."""

    position_mm: float
    limits: AxisDynamicsLimits
    velocity_mm_s: float = 0.0
    target_mm: float | None = None  # goal of an increment, the handwheel, homing
    direction: int = 0  # continuous jog: +1 / -1 toward that software limit; 0 = none
    hit_limit: bool = False  # the goal was cut at a software limit (or the jog reached it)
    _dt_s: float = 0.001  # the cycle time of the last step
    _arrived_last_cycle: bool = False  # the goal was reached in the last step

    @property
    def at_rest(self) -> bool:
        """No goal and no velocity: the motion is over."""
        return (self.target_mm is None and self.direction == 0
                and abs(self.velocity_mm_s) < _STANDSTILL_MM_S
                and not self._arrived_last_cycle)

    def move_to(self, target_mm: float) -> None:
        """Go to ``target_mm`` (cut at the software limits; ``hit_limit`` when cut)."""
        clipped = self.limits.clip(target_mm)
        self.hit_limit = clipped != target_mm
        self.target_mm, self.direction = clipped, 0

    def move_by(self, distance_mm: float) -> None:
        """Add ``distance_mm`` to the goal (from the position when there is none)."""
        base = self.target_mm if self.target_mm is not None else self.position_mm
        self.move_to(base + distance_mm)

    def run(self, direction: int) -> None:
        """Continuous jog toward the software limit in ``direction`` (+1 or -1)."""
        self.target_mm, self.direction, self.hit_limit = None, direction, False

    def stop(self) -> None:
        """Brake to standstill under the acceleration (key released, feedhold)."""
        self.target_mm, self.direction = None, 0

    def step(self, dt_s: float) -> float:
        """Advance one cycle; returns the new position."""
        self._dt_s = dt_s
        if self._arrived_last_cycle:  # at the goal: this cycle the velocity is 0
            self._arrived_last_cycle = False
            self.velocity_mm_s = 0.0
            if self._goal() is None:
                return self.position_mm
        acc = self.limits.acc_mm_s2
        wanted = self._wanted_velocity()
        dv = max(-acc * dt_s, min(acc * dt_s, wanted - self.velocity_mm_s))
        velocity = self.velocity_mm_s + dv
        position = self.position_mm + velocity * dt_s
        goal = self._goal()
        if goal is not None and ((goal - position) * (goal - self.position_mm) <= 0.0
                                 or abs(goal - position) <= _AT_GOAL_MM):
            # reached the goal this cycle at this velocity (at most acc * dt): the
            # velocity shows for this cycle, the next one stands
            position = goal
            self._arrived_last_cycle = True
            self._arrived()
        clipped = self.limits.clip(position)
        if clipped != position:  # braking from a fast jog may not pass a limit either
            position, velocity, self.hit_limit = clipped, 0.0, True
            self.stop()
        self.position_mm, self.velocity_mm_s = position, velocity
        if abs(velocity) < _STANDSTILL_MM_S and goal is None:
            self.velocity_mm_s = 0.0
        return position

    def _goal(self) -> float | None:
        if self.target_mm is not None:
            return self.target_mm
        if self.direction > 0:
            return self.limits.sw_limit_max_mm
        if self.direction < 0:
            return self.limits.sw_limit_min_mm
        return None

    def _wanted_velocity(self) -> float:
        """The velocity the axis should have now: toward the goal as fast as it may and
        still stop there; 0 without a goal."""
        goal = self._goal()
        if goal is None:
            return 0.0
        distance = goal - self.position_mm
        if abs(distance) < _AT_GOAL_MM:
            return 0.0
        # Braking cycle by cycle from v (v, v - a dt, ... down to 0, each for dt) covers
        # at most v^2 / 2a + v dt / 2 + a dt^2 / 8 = (v + a dt / 2)^2 / 2a: the fastest v
        # that still stops within the distance is sqrt(2 a d) - a dt / 2. The last bit
        # (d <= a dt^2 / 2) is covered in one cycle at d / dt <= a dt / 2.
        acc, dt = self.limits.acc_mm_s2, self._dt_s
        half_step = acc * dt / 2.0
        reachable = max(math.sqrt(2.0 * acc * abs(distance)) - half_step,
                        min(abs(distance) / dt, half_step))
        return math.copysign(min(self.limits.vel_mm_s, reachable), distance)

    def _arrived(self) -> None:
        if self.direction != 0:  # a continuous jog ran into the software limit
            self.hit_limit = True
        self.target_mm, self.direction = None, 0
