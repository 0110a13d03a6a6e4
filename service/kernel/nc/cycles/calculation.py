"""The calculation cycles: least-squares fits of measured points (CYCLES-ADC §4).

Points are passed in @P50..@P59 (X), @P60..@P69 (Y), @P70..@P79 (Z, not for the 2D
circle), point k in @P5k/@P6k/@P7k, at most 10. The points are given in order: point
k+1 only with point k, and every coordinate of a given point. The fits are the
geometric least-squares fits of ``fitting``; degenerate points (identical, collinear,
coplanar) are an error with their own id, never a number. The results go to the
caller's ``V.CYC.SysRet*`` variables; components of result points and unit vectors that
are rounding noise (below 1e-13 relative to the largest coordinate, resp. to 1) are
set to 0, so exact input prints exact output (no ``-0.000000``).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import TypeVar

from ..errors import NcErrorId
from ..variables import Value
from .fitting import (
    Degeneracy,
    FitError,
    fit_circle_2d,
    fit_circle_3d,
    fit_line,
    fit_plane,
    fit_sphere,
)
from .spec import BuiltinCycle, CycleContext, ParamProblem, ParamSpec

Fit = TypeVar("Fit")  # the result of one of the fits

MAX_POINTS = 10
_NOISE = 1e-13  # result components this small (relative to the points) are rounding noise
_AXES = ("X", "Y", "Z")
_ERROR_OF = {
    Degeneracy.IDENTICAL: NcErrorId.CYCLE_POINTS_IDENTICAL,
    Degeneracy.COLLINEAR: NcErrorId.CYCLE_POINTS_COLLINEAR,
    Degeneracy.COPLANAR: NcErrorId.CYCLE_POINTS_COPLANAR,
}


def _point_params(dims: int) -> dict[int, ParamSpec]:
    return {50 + 10 * d + k: ParamSpec(f"{_AXES[d]} coordinate of point {k + 1}")
            for d in range(dims) for k in range(MAX_POINTS)}


def _points_check(
    name: str, dims: int, minimum: int,
) -> Callable[[Mapping[int, Value]], list[ParamProblem]]:
    def check(values: Mapping[int, Value]) -> list[ParamProblem]:
        problems: list[ParamProblem] = []
        count = sum(1 for k in range(MAX_POINTS) if 50 + k in values)
        for k in range(MAX_POINTS):
            given = [50 + 10 * d + k in values for d in range(dims)]
            if k < max(count, minimum):
                for d in range(dims):
                    if not given[d]:
                        what = (f"point {k + 1} needs @P{50 + 10 * d + k} ({_AXES[d]})"
                                if k < count or any(given) else
                                f"{name} needs at least {minimum} points: @P{50 + 10 * d + k} "
                                f"({_AXES[d]} of point {k + 1}) is missing")
                        problems.append(ParamProblem(NcErrorId.CYCLE_PARAMETER_MISSING,
                                                     None, what))
            elif any(given):
                first = next(50 + 10 * d + k for d in range(dims) if given[d])
                problems.append(ParamProblem(
                    NcErrorId.CYCLE_PARAMETER_MISSING, first,
                    f"@P{first} gives point {k + 1}, but point {count + 1} is missing "
                    f"(@P{50 + count}): points are given in order"))
        return problems
    return check


def _points(values: Mapping[int, Value], dims: int) -> list[tuple[float, ...]]:
    points: list[tuple[float, ...]] = []
    for k in range(MAX_POINTS):
        if 50 + k not in values:
            break
        points.append(tuple(float(values[50 + 10 * d + k]) for d in range(dims)))
    return points


def _fitted(
    context: CycleContext, name: str, fit: Callable[[Sequence[Sequence[float]]], Fit],
    points: list[tuple[float, ...]],
) -> tuple[Fit, float]:
    """The fit of ``points`` and their scale (1 + the largest coordinate's size)."""
    try:
        result = fit(points)
    except FitError as fault:
        err_id = _ERROR_OF.get(fault.degeneracy, NcErrorId.CYCLE_PARAMETER_RANGE)
        raise context.error(err_id, f"{name}: {fault.message}") from None
    return result, 1.0 + max(abs(c) for point in points for c in point)


def _position(scale: float, value: float) -> float:
    """A coordinate of a result point: rounding noise (relative to the points' ``scale``)
    is 0, so that the unit circle's centre prints as 0.000000, not -0.000000."""
    return 0.0 if abs(value) <= _NOISE * scale else value


def _unit(value: float) -> float:
    """A component of a result unit vector: rounding noise is 0."""
    return 0.0 if abs(value) <= _NOISE else value


def _circle(context: CycleContext, name: str) -> None:
    result, scale = _fitted(context, name, fit_circle_2d, _points(context.params, 2))
    context.set_output("SysRetCenterX", _position(scale, result.center_x))
    context.set_output("SysRetCenterY", _position(scale, result.center_y))
    context.set_output("SysRetRadius", result.radius)
    context.set_output("SysRetVariance", result.variance)


def _plane(context: CycleContext, name: str) -> None:
    result, scale = _fitted(context, name, fit_plane, _points(context.params, 3))
    for axis, n, s in zip(_AXES, result.normal, result.support, strict=True):
        context.set_output(f"SysRetNormal{axis}", _unit(n))
        context.set_output(f"SysRetSupVector{axis}", _position(scale, s))


def _line(context: CycleContext, name: str) -> None:
    result, scale = _fitted(context, name, fit_line, _points(context.params, 3))
    for axis, d, s in zip(_AXES, result.direction, result.support, strict=True):
        context.set_output(f"SysRetDirVector{axis}", _unit(d))
        context.set_output(f"SysRetSupVector{axis}", _position(scale, s))
    context.set_output("SysRetVariance", result.variance)


def _sphere(context: CycleContext, name: str) -> None:
    result, scale = _fitted(context, name, fit_sphere, _points(context.params, 3))
    for axis, c in zip(_AXES, result.center, strict=True):
        context.set_output(f"SysRetCenter{axis}", _position(scale, c))
    context.set_output("SysRetRadius", result.radius)
    context.set_output("SysRetVariance", result.variance)


def _plane_circle(context: CycleContext, name: str) -> None:
    result, scale = _fitted(context, name, fit_circle_3d, _points(context.params, 3))
    for axis, c, n in zip(_AXES, result.center, result.normal, strict=True):
        context.set_output(f"SysRetCenter{axis}", _position(scale, c))
        context.set_output(f"SysRetNormal{axis}", _unit(n))
    context.set_output("SysRetRadius", result.radius)
    context.set_output("SysRetRadVariance", result.radius_variance)


def _cycle(
    name: str, dims: int, minimum: int, run: Callable[[CycleContext, str], None],
) -> BuiltinCycle:
    def body(context: CycleContext) -> None:
        run(context, name)  # a calculation has no motion part: the body returns None

    return BuiltinCycle(name, _point_params(dims), body, _points_check(name, dims, minimum))


CALCULATION_CYCLES = (
    _cycle("SysCalcCircle.ecy", 2, 3, _circle),
    _cycle("SysCalcPlane.ecy", 3, 3, _plane),
    _cycle("SysCalcLine.ecy", 3, 2, _line),
    _cycle("SysCalcSphere.ecy", 3, 4, _sphere),
    _cycle("SysCalcPlaneCircle.ecy", 3, 3, _plane_circle),
)
