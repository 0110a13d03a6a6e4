"""A five-axis machine's kinematic chain: where the tool tip is for given axis values,
and the axis values for a given tool tip and tool orientation.

The chain is described as ISG's Universal Kinematics (kinematic ID 91) describes it
(infosys.beckhoff.com tf5240_universal_kinematic, "Example of an AC machine with
cardanic table" 278732555 and the parameters P-CHAN-00285 .. P-CHAN-00293):

* the tool's zero orientation (P-CHAN-00285, the direction the tool points in, from
  its tip towards the spindle) and zero position (P-CHAN-00286) with all axes at 0;
* the axes in the sequence they have along the chain from the workpiece to the machine
  origin and from there to the tool tip (P-CHAN-00290), each a translator or a rotator
  (P-CHAN-00291) with a direction (P-CHAN-00292) and, for a rotator, a point on its
  line (P-CHAN-00293). An axis on the workpiece side moves the workpiece, not the
  tool: its direction is given multiplied by -1, as ISG asks.

Moving along the chain from the tool back to the workpiece, each axis moves everything
after it: the tool tip in workpiece coordinates is ``M0(q0) M1(q1) .. Mn(qn) p0`` with
``Mk`` a shift by ``qk`` along a translator's direction or a turn by ``qk`` degrees
about a rotator's line (right-hand rule), and the tool direction is the rotators' turns
applied to the zero orientation.

With RTCP (``#TRAFO ON``) the program gives the tool tip and the rotary axes: the
translators' values then follow from a 3x3 linear system, because the tip is affine in
them (``tip_to_axes``). SysPosRotationToPlane and ``#CS`` with the tool turned need the
rotary values for a tool direction: two rotators give two solutions in general (ISG
picks the one nearer the current position), and none when the direction lies outside
the cone the rotators can reach (``orientation_to_rotary``).

Pure Python on tuples, as ``cycles.rotation``: this runs every interpolation cycle
while a transformation is on, where numpy's per-call set-up costs more than the sums.
"""

from __future__ import annotations

import enum
import math
from collections.abc import Sequence
from dataclasses import dataclass

from ..nc.cycles.rotation import IDENTITY, Matrix, Vector, apply, multiply

# squared distance of a unit vector from a rotator's line below this: it lies on the
# line (singular). The solution's accuracy near that pose is ~1e-8 rad anyway (1 - cos
# cancels), far below the axes' resolution of 0.0001 degrees (1.7e-6 rad).
_PARALLEL_TOLERANCE = 1e-18
# a tool direction this far outside what the rotators reach is unreachable
_REACH_TOLERANCE = 1e-9
# the translators' directions (turned) must span space: |det| of unit vectors above this
_SPAN_TOLERANCE = 1e-6


class JointKind(enum.IntEnum):
    """What an axis of the chain does (P-CHAN-00291 ``axis[k].type``)."""

    TRANSLATOR = 1
    ROTATOR = 2


class KinematicsError(ValueError):
    """The chain is not a five-axis machine, or a pose cannot be reached."""


@dataclass(frozen=True, slots=True)
class ChainAxis:
    """One axis of the kinematic chain."""

    axis_index: int  # the channel axis that drives it
    kind: JointKind
    direction: Vector  # unit vector; -1 times the axis direction on the workpiece side
    point_mm: Vector = (0.0, 0.0, 0.0)  # a point on a rotator's line


@dataclass(frozen=True, slots=True)
class Pose:
    """The tool tip and the tool direction (unit, tip towards spindle)."""

    tip_mm: Vector
    orientation: Vector


def _vector(v: Sequence[float], what: str) -> Vector:
    if len(v) != 3:
        raise KinematicsError(f"{what} needs 3 values (X, Y, Z), not {len(v)}")
    return (float(v[0]), float(v[1]), float(v[2]))


def _unit(v: Sequence[float]) -> Vector:
    x, y, z = _vector(v, "a direction")
    n = math.sqrt(x * x + y * y + z * z)
    if n == 0.0 or not math.isfinite(n):
        raise KinematicsError(f"direction {tuple(v)} is not a vector (zero or not finite)")
    return (x / n, y / n, z / n)


def _cross(a: Vector, b: Vector) -> Vector:
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _dot(a: Vector, b: Vector) -> float:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _det(a: Vector, b: Vector, c: Vector) -> float:
    return _dot(a, _cross(b, c))


def turn(direction: Vector, angle_deg: float) -> Matrix:
    """Rotation by ``angle_deg`` about the unit vector ``direction`` (Rodrigues)."""
    if angle_deg % 90.0 == 0.0:  # exact quarter turns: clean zeros in the positions
        c, s = ((1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0))[int(angle_deg // 90) % 4]
    else:
        rad = math.radians(angle_deg)
        c, s = math.cos(rad), math.sin(rad)
    x, y, z = direction
    t = 1.0 - c
    return ((c + x * x * t, x * y * t - z * s, x * z * t + y * s),
            (y * x * t + z * s, c + y * y * t, y * z * t - x * s),
            (z * x * t - y * s, z * y * t + x * s, c + z * z * t))


def _turn_about(axis: ChainAxis, angle_deg: float, p: Vector) -> Vector:
    rot = turn(axis.direction, angle_deg)
    ox, oy, oz = axis.point_mm
    x, y, z = apply(rot, (p[0] - ox, p[1] - oy, p[2] - oz))
    return (x + ox, y + oy, z + oz)


def _angle_deg(rad: float) -> float:
    return math.degrees(rad) + 0.0


@dataclass(frozen=True, slots=True)
class Kinematics:
    """A five-axis chain: three translators and two rotators (``from_chain`` checks)."""

    kinematic_id: int
    zero_orientation: Vector  # unit
    zero_position_mm: Vector
    chain: tuple[ChainAxis, ...]
    # the rotators' ranges (degrees, their software limits): a tool direction is turned
    # to by values inside them
    rotary_limits_deg: tuple[tuple[int, float, float], ...] = ()

    @classmethod
    def from_chain(cls, kinematic_id: int, zero_orientation: Sequence[float],
                   zero_position_mm: Sequence[float], chain: Sequence[ChainAxis],
                   rotary_limits_deg: Sequence[tuple[int, float, float]] = ()) -> Kinematics:
        """Check and normalise a configured chain: three translators whose directions
        span space, two rotators, each channel axis once; ``rotary_limits_deg``: (axis
        index, lowest, highest) of rotators with a range."""
        axes = tuple(ChainAxis(a.axis_index, JointKind(a.kind), _unit(a.direction),
                               _vector(a.point_mm, "a rotator's point"))
                     for a in chain)
        kinds = [a.kind for a in axes]
        if kinds.count(JointKind.TRANSLATOR) != 3 or kinds.count(JointKind.ROTATOR) != 2:
            raise KinematicsError(
                f"kinematics {kinematic_id}: a five-axis chain has 3 translators and 2 "
                f"rotators, this one has {kinds.count(JointKind.TRANSLATOR)} and "
                f"{kinds.count(JointKind.ROTATOR)}")
        indices = [a.axis_index for a in axes]
        if len(set(indices)) != len(indices):
            raise KinematicsError(f"kinematics {kinematic_id}: an axis is in the chain twice "
                                  f"(axis indices {indices})")
        made = cls(kinematic_id, _unit(zero_orientation),
                   _vector(zero_position_mm, "the zero position"), axes,
                   tuple(rotary_limits_deg))
        a, b, c = made._translator_columns({})
        if abs(_det(a, b, c)) < _SPAN_TOLERANCE:
            raise KinematicsError(f"kinematics {kinematic_id}: the translators' directions "
                                  f"do not span space")
        return made

    @property
    def rotators(self) -> tuple[ChainAxis, ChainAxis]:
        """The two rotators in chain order (workpiece side first)."""
        first, second = (a for a in self.chain if a.kind == JointKind.ROTATOR)
        return first, second

    @property
    def translators(self) -> tuple[ChainAxis, ChainAxis, ChainAxis]:
        """The three translators in chain order."""
        a, b, c = (a for a in self.chain if a.kind == JointKind.TRANSLATOR)
        return a, b, c

    def forward(self, axis_values: dict[int, float], tool_length_mm: float = 0.0) -> Pose:
        """The tool tip (workpiece coordinates, mm) and direction for the axis values
        (channel axis index -> mm or degrees); the tool length lies along the tool."""
        o = self.zero_orientation
        zx, zy, zz = self.zero_position_mm
        p: Vector = (zx - tool_length_mm * o[0], zy - tool_length_mm * o[1],
                     zz - tool_length_mm * o[2])
        rot = IDENTITY
        for axis in reversed(self.chain):
            q = axis_values.get(axis.axis_index, 0.0)
            if axis.kind == JointKind.TRANSLATOR:
                d = axis.direction
                p = (p[0] + q * d[0], p[1] + q * d[1], p[2] + q * d[2])
            else:
                p = _turn_about(axis, q, p)
                rot = multiply(turn(axis.direction, q), rot)
        return Pose(p, apply(rot, o))

    def _translator_columns(self, rotary_deg: dict[int, float]) -> tuple[Vector, Vector, Vector]:
        """Each translator's direction as seen at the tool tip: turned by the rotators
        before it in the chain."""
        columns: list[Vector] = []
        rot = IDENTITY
        for axis in self.chain:
            if axis.kind == JointKind.ROTATOR:
                rot = multiply(rot, turn(axis.direction, rotary_deg.get(axis.axis_index, 0.0)))
            else:
                columns.append(apply(rot, axis.direction))
        a, b, c = columns
        return a, b, c

    def tip_to_axes(self, tip_mm: Vector, rotary_deg: dict[int, float],
                    tool_length_mm: float = 0.0) -> dict[int, float]:
        """RTCP: the translators' values that put the tool tip at ``tip_mm`` with the
        rotators at ``rotary_deg``; returns every chain axis's value. (One pass each way
        over the chain, each rotator's turn built once: this runs every cycle.)"""
        turns = {a.axis_index: turn(a.direction, rotary_deg.get(a.axis_index, 0.0))
                 for a in self.chain if a.kind == JointKind.ROTATOR}
        o = self.zero_orientation
        zx, zy, zz = self.zero_position_mm
        p: Vector = (zx - tool_length_mm * o[0], zy - tool_length_mm * o[1],
                     zz - tool_length_mm * o[2])
        for axis in reversed(self.chain):  # the tip with every translator at 0
            if axis.kind == JointKind.ROTATOR:
                ox, oy, oz = axis.point_mm
                x, y, z = apply(turns[axis.axis_index], (p[0] - ox, p[1] - oy, p[2] - oz))
                p = (x + ox, y + oy, z + oz)
        columns: list[Vector] = []
        rot = IDENTITY
        for axis in self.chain:  # each translator's direction as seen at the tip
            if axis.kind == JointKind.ROTATOR:
                rot = multiply(rot, turns[axis.axis_index])
            else:
                columns.append(apply(rot, axis.direction))
        a, b, c = columns
        r = (tip_mm[0] - p[0], tip_mm[1] - p[1], tip_mm[2] - p[2])
        det = _det(a, b, c)
        solved = (_det(r, b, c) / det, _det(a, r, c) / det, _det(a, b, r) / det)
        values = dict(rotary_deg)
        for axis, q in zip(self.translators, solved, strict=True):
            values[axis.axis_index] = q + 0.0
        return values

    def orientation_to_rotary(self, orientation: Vector,
                              near_deg: dict[int, float]) -> dict[int, float]:
        """The rotators' values (degrees) that turn the tool to ``orientation``; of the
        two solutions the one nearer ``near_deg`` (the current values), each angle
        chosen nearest its current value modulo 360. When the direction lies on the first
        rotator's line (a singular pose: that axis is free) it keeps its value.
        ``KinematicsError`` when the rotators cannot reach the direction."""
        d = _unit(orientation)
        first, second = self.rotators
        u1, u2, z0 = first.direction, second.direction, self.zero_orientation
        # R1(t1) R2(t2) z0 = d  <=>  R2(t2) z0 = R1(-t1) d = c, where c has the same
        # component along u1 as d and along u2 as z0 (rotations keep them), |c| = 1
        # (Paden-Kahan subproblem 2)
        a_, b_ = _dot(u1, d), _dot(u2, z0)
        k = _dot(u1, u2)
        den = 1.0 - k * k
        if den < _PARALLEL_TOLERANCE:
            raise KinematicsError(f"kinematics {self.kinematic_id}: the rotators are parallel")
        alpha = (a_ - k * b_) / den
        beta = (b_ - k * a_) / den
        w = _cross(u1, u2)
        rest = 1.0 - alpha * alpha - beta * beta - 2.0 * alpha * beta * k
        if rest < -_REACH_TOLERANCE:
            raise KinematicsError(
                f"kinematics {self.kinematic_id}: the tool direction "
                f"({d[0]:.6g}, {d[1]:.6g}, {d[2]:.6g}) is out of the rotators' reach")
        gamma = math.sqrt(max(rest, 0.0) / _dot(w, w))
        base = (alpha * u1[0] + beta * u2[0], alpha * u1[1] + beta * u2[1],
                alpha * u1[2] + beta * u2[2])
        best: tuple[float, dict[int, float]] | None = None
        for sign in ((1.0, -1.0) if gamma > 0.0 else (1.0,)):
            c = (base[0] + sign * gamma * w[0], base[1] + sign * gamma * w[1],
                 base[2] + sign * gamma * w[2])
            t2 = self._angle_between(u2, z0, c, near_deg.get(second.axis_index, 0.0))
            t1 = self._angle_between(u1, c, d, near_deg.get(first.axis_index, 0.0))
            candidate = {first.axis_index: t1, second.axis_index: t2}
            if not self._within_limits(candidate):
                continue
            distance = sum(abs(v - near_deg.get(i, 0.0)) for i, v in candidate.items())
            if best is None or distance < best[0]:
                best = (distance, candidate)
        if best is None:
            raise KinematicsError(
                f"kinematics {self.kinematic_id}: the tool direction ({d[0]:.6g}, "
                f"{d[1]:.6g}, {d[2]:.6g}) needs the rotary axes beyond their limits")
        return best[1]

    def _within_limits(self, values: dict[int, float]) -> bool:
        """The rotators' ``values`` lie in their ranges (a range of a full turn or more
        takes the value modulo 360 nearest to the one found)."""
        for index, low, high in self.rotary_limits_deg:
            value = values[index]
            if low <= value <= high:
                continue
            if high - low >= 360.0:  # another turn of the same angle is inside
                shifted = value + 360.0 * math.ceil((low - value) / 360.0)
                if shifted <= high:
                    values[index] = shifted
                    continue
            return False
        return True

    @staticmethod
    def _angle_between(u: Vector, p: Vector, q: Vector, near: float) -> float:
        """The angle about ``u`` that turns ``p`` onto ``q`` (subproblem 1), nearest
        ``near`` modulo 360; ``near`` itself when both lie on ``u`` (free)."""
        pp = (p[0] - _dot(u, p) * u[0], p[1] - _dot(u, p) * u[1], p[2] - _dot(u, p) * u[2])
        qq = (q[0] - _dot(u, q) * u[0], q[1] - _dot(u, q) * u[1], q[2] - _dot(u, q) * u[2])
        if _dot(pp, pp) < _PARALLEL_TOLERANCE or _dot(qq, qq) < _PARALLEL_TOLERANCE:
            return near  # on the axis: any angle does; keep the axis where it is
        angle = _angle_deg(math.atan2(_dot(u, _cross(pp, qq)), _dot(pp, qq)))
        return angle + 360.0 * round((near - angle) / 360.0)

    def to_program(self, axes_mm: Sequence[float], xyz: tuple[int, int, int],
                   tool_length_mm: float) -> tuple[float, ...]:
        """A channel's axis positions as ``#TRAFO ON`` programs them: the channel axes
        ``xyz`` hold the tool tip relative to the tool's zero position (so that with the
        rotary axes at 0 a tip is where a three-axis channel puts it), the rest stay."""
        tip = self.forward(dict(enumerate(axes_mm)), tool_length_mm).tip_mm
        out = list(axes_mm)
        for k, value, zero in zip(xyz, tip, self.zero_position_mm, strict=True):
            out[k] = value - zero + 0.0
        return tuple(out)

    def to_axes(self, program_mm: Sequence[float], xyz: tuple[int, int, int],
                tool_length_mm: float) -> tuple[float, ...]:
        """The inverse of ``to_program``: the axis positions for a programmed tip and
        rotary positions (RTCP)."""
        zx, zy, zz = self.zero_position_mm
        tip = (program_mm[xyz[0]] + zx, program_mm[xyz[1]] + zy, program_mm[xyz[2]] + zz)
        first, second = self.rotators
        values = self.tip_to_axes(tip, {first.axis_index: program_mm[first.axis_index],
                                        second.axis_index: program_mm[second.axis_index]},
                                  tool_length_mm)
        out = list(program_mm)
        for k, value in values.items():
            out[k] = value
        return tuple(out)
