"""Least-squares fits of the calculation cycles (SysCalcCircle, ...Plane, ...Line,
...Sphere, ...PlaneCircle): documentation examples, exact fits, noisy fits against an
independent computation, degenerate input, sign conventions."""

from __future__ import annotations

import dataclasses
import math
import re
import time

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cnc_objects.service.kernel.nc.cycles.fitting import (
    MAX_POINTS,
    Circle3dFit,
    CircleFit,
    Degeneracy,
    FitError,
    LineFit,
    PlaneFit,
    SphereFit,
    fit_circle_2d,
    fit_circle_3d,
    fit_line,
    fit_plane,
    fit_sphere,
)

EXACT = 1e-9
CENTRE_2D = (12.5, -7.25)
CENTRE_3D = (12.5, -7.25, 3.0)
RADIUS = 37.5


# --- helpers -----------------------------------------------------------------------------


def close(actual, expected, tol=EXACT) -> bool:
    """Every component within ``tol`` (absolute)."""
    a = np.atleast_1d(np.asarray(actual, dtype=float))
    e = np.atleast_1d(np.asarray(expected, dtype=float))
    return a.shape == e.shape and bool(np.all(np.abs(a - e) <= tol))


def arc_2d(centre, radius, degrees) -> list[tuple[float, float]]:
    return [(centre[0] + radius * math.cos(math.radians(a)),
             centre[1] + radius * math.sin(math.radians(a))) for a in degrees]


def unit(v) -> np.ndarray:
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v)


def plane_basis(normal) -> tuple[np.ndarray, np.ndarray]:
    """Two unit vectors spanning the plane perpendicular to ``normal``."""
    n = unit(normal)
    helper = np.array([1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    u = unit(np.cross(n, helper))
    return u, np.cross(n, u)


def arc_3d(centre, radius, normal, degrees) -> list[tuple[float, float, float]]:
    u, v = plane_basis(normal)
    c = np.asarray(centre, dtype=float)
    return [tuple(float(x) for x in c + radius * (math.cos(math.radians(a)) * u
                                                  + math.sin(math.radians(a)) * v))
            for a in degrees]


def sphere_points(centre, radius, directions) -> list[tuple[float, float, float]]:
    c = np.asarray(centre, dtype=float)
    return [tuple(float(x) for x in c + radius * unit(d)) for d in directions]


def oriented(v) -> np.ndarray:
    """The documented sign convention, written independently: +Z, else +Y, else +X."""
    v = np.asarray(v, dtype=float)
    for k in (2, 1, 0):
        if abs(v[k]) > 1e-12:
            return v if v[k] > 0 else -v
    raise AssertionError("zero vector")


def radial_ssr(points, centre) -> float:
    """Sum of squared geometric residuals d_i - r with r the mean distance."""
    d = np.linalg.norm(np.asarray(points, dtype=float) - np.asarray(centre, dtype=float), axis=1)
    return float(np.sum((d - d.mean()) ** 2))


def newton_centre(points, start, h=1e-4, iterations=40) -> np.ndarray:
    """Independent geometric fit: Newton on the centre with numerically differentiated
    objective sum (d_i - mean d)^2 (central differences for gradient and Hessian)."""
    p = np.asarray(points, dtype=float)
    c = np.asarray(start, dtype=float)
    eye = np.eye(len(c)) * h

    def cost(x):
        return radial_ssr(p, x)

    for _ in range(iterations):
        g = np.array([(cost(c + e) - cost(c - e)) / (2 * h) for e in eye])
        hess = np.array([[(cost(c + a + b) - cost(c + a - b) - cost(c - a + b)
                           + cost(c - a - b)) / (4 * h * h) for b in eye] for a in eye])
        c = c - np.linalg.solve(hess, g)
    return c


def kasa_centre(points) -> np.ndarray:
    """The algebraic fit |p|^2 = 2 c.p + k, solved directly."""
    p = np.asarray(points, dtype=float)
    design = np.column_stack([2 * p, np.ones(len(p))])
    solution, *_ = np.linalg.lstsq(design, np.sum(p * p, axis=1), rcond=None)
    return solution[:-1]


def noisy(points, sigma, seed) -> list[tuple[float, ...]]:
    rng = np.random.default_rng(seed)
    p = np.asarray(points, dtype=float)
    return [tuple(float(x) for x in row) for row in p + rng.normal(0.0, sigma, p.shape)]


def radially_noisy_2d(centre, radius, degrees, sigma, seed):
    rng = np.random.default_rng(seed)
    return [(centre[0] + (radius + e) * math.cos(math.radians(a)),
             centre[1] + (radius + e) * math.sin(math.radians(a)))
            for a, e in zip(degrees, rng.normal(0.0, sigma, len(degrees)))]


# --- documentation examples --------------------------------------------------------------


def test_doc_example_circle() -> None:
    fit = fit_circle_2d([(0, -1), (0, 1), (1, 0), (-1, 0)])
    assert close((fit.center_x, fit.center_y), (0, 0))
    assert close(fit.radius, 1)
    assert close(fit.variance, 0, 1e-20)


def test_doc_example_plane() -> None:
    fit = fit_plane([(1, 0, 0), (0, 1, 0), (1, 1, 0)])
    assert close(fit.normal, (0, 0, 1))
    assert close(fit.support, (2 / 3, 2 / 3, 0))


def test_doc_example_line() -> None:
    fit = fit_line([(0, 0, 0), (1, 0, 0), (2, 0, 0)])
    assert close(fit.direction, (1, 0, 0))
    assert close(fit.support, (1, 0, 0))
    assert close(fit.variance, 0, 1e-20)


def test_doc_example_sphere() -> None:
    fit = fit_sphere([(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1)])
    assert close(fit.center, (0, 0, 0))
    assert close(fit.radius, 1)
    assert close(fit.variance, 0, 1e-20)


def test_doc_example_circle_3d() -> None:
    fit = fit_circle_3d([(1, 0, 1), (0, 1, 1), (-1, 0, 1), (0, -1, 1)])
    assert close(fit.center, (0, 0, 1))
    assert close(fit.radius, 1)
    assert close(fit.normal, (0, 0, 1))
    assert close(fit.radius_variance, 0, 1e-20)


# --- result types ------------------------------------------------------------------------


def test_results_are_plain_python_floats_and_frozen() -> None:
    results = [
        fit_circle_2d(arc_2d(CENTRE_2D, RADIUS, [0, 100, 200])),
        fit_plane([(1, 0, 0), (0, 1, 0), (1, 1, 0.5)]),
        fit_line([(0, 0, 0), (1, 2, 3)]),
        fit_sphere([(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, 0, 1)]),
        fit_circle_3d([(1, 0, 1), (0, 1, 1), (-1, 0, 1)]),
    ]
    assert [type(r) for r in results] == [CircleFit, PlaneFit, LineFit, SphereFit, Circle3dFit]
    for result in results:
        for field in dataclasses.fields(result):
            value = getattr(result, field.name)
            if isinstance(value, tuple):
                assert len(value) == 3
                assert all(type(x) is float for x in value), (field.name, value)
            else:
                assert type(value) is float, (field.name, value)
        with pytest.raises(dataclasses.FrozenInstanceError):
            setattr(result, dataclasses.fields(result)[0].name, 0.0)
        assert not hasattr(result, "__dict__")  # slots


# --- exact fits --------------------------------------------------------------------------


@pytest.mark.parametrize("degrees", [
    [10, 40, 70],                      # 3 points on a 60 degree arc
    [-30, -10, 0, 30],                 # 4 points on a 60 degree arc
    [0, 36, 72, 108, 144, 180, 216, 252, 288, 324],  # 10 points, full circle
    [200, 201, 203, 207],              # 7 degree arc
])
def test_circle_2d_exact(degrees) -> None:
    fit = fit_circle_2d(arc_2d(CENTRE_2D, RADIUS, degrees))
    assert close((fit.center_x, fit.center_y), CENTRE_2D)
    assert close(fit.radius, RADIUS)
    assert 0.0 <= fit.variance <= 1e-20


def test_circle_2d_exact_far_from_origin_and_tiny() -> None:
    fit = fit_circle_2d(arc_2d((1.0e4, -2.5e4), 0.5, [0, 50, 100, 150]))
    assert close((fit.center_x, fit.center_y), (1.0e4, -2.5e4))
    assert close(fit.radius, 0.5)
    tiny = fit_circle_2d(arc_2d((0.0, 0.0), 1e-6, [0, 120, 240]))
    assert close(tiny.radius, 1e-6, 1e-15)


def test_circle_2d_large_radius_through_nearly_straight_points() -> None:
    # Sagitta 1e-3 on a chord of 2: radius (1 + 1e-6) / 2e-3, clearly not collinear.
    fit = fit_circle_2d([(0, 0), (1, 1e-3), (2, 0)])
    radius = (1 + 1e-6) / 2e-3
    assert close(fit.radius, radius, 1e-7)
    assert close((fit.center_x, fit.center_y), (1, 1e-3 - radius), 1e-7)


@pytest.mark.parametrize("normal", [(0, 0, 1), (1, 2, 3), (-3, 1, 0.5), (1, 0, 0)])
@pytest.mark.parametrize("degrees", [[10, 40, 70], [0, 36, 72, 108, 144, 180, 216, 252, 288, 324]])
def test_circle_3d_exact(normal, degrees) -> None:
    fit = fit_circle_3d(arc_3d(CENTRE_3D, RADIUS, normal, degrees))
    assert close(fit.center, CENTRE_3D)
    assert close(fit.radius, RADIUS)
    assert close(fit.normal, oriented(unit(normal)))
    assert 0.0 <= fit.radius_variance <= 1e-20


@pytest.mark.parametrize("normal", [(1, 2, 3), (-3, 1, 0.5), (0.2, -0.1, -1)])
@pytest.mark.parametrize("count", [3, 10])
def test_plane_exact_tilted(normal, count) -> None:
    u, v = plane_basis(normal)
    rng = np.random.default_rng(count)
    support = np.array(CENTRE_3D)
    points = [tuple(float(x) for x in support + a * u + b * v)
              for a, b in rng.uniform(-50, 50, (count, 2))]
    fit = fit_plane(points)
    assert close(fit.normal, oriented(unit(normal)))
    assert close(fit.support, np.mean(points, axis=0))
    assert close(np.linalg.norm(fit.normal), 1.0)


@pytest.mark.parametrize("count", [2, 3, 10])
def test_line_exact_with_negative_direction(count) -> None:
    direction = unit((-1, 2, -2))
    start = np.array([5.0, 3.0, -2.0])
    points = [tuple(float(x) for x in start + t * direction)
              for t in np.linspace(0, 40, count)]
    fit = fit_line(points)
    assert close(fit.direction, direction)
    assert close(fit.support, np.mean(points, axis=0))
    assert 0.0 <= fit.variance <= 1e-20


@pytest.mark.parametrize("directions", [
    [(1, 0, 0), (0, 1, 0), (0, 0, 1), (-1, -1, -1)],                          # 4 points
    [(1, 0.2, 0.5), (0.3, 1, 0.6), (-0.4, 0.5, 1), (0.5, -0.6, 0.8), (-0.2, -0.3, 1.5)],  # cap
    [(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1),
     (1, 1, 1), (-1, 1, -1), (1, -1, 0.5), (-0.3, -1, 1)],                     # 10 points
])
def test_sphere_exact(directions) -> None:
    fit = fit_sphere(sphere_points(CENTRE_3D, RADIUS, directions))
    assert close(fit.center, CENTRE_3D)
    assert close(fit.radius, RADIUS)
    assert 0.0 <= fit.variance <= 1e-20


# --- noisy fits against an independent computation ---------------------------------------


@pytest.mark.parametrize("degrees", [list(range(0, 360, 36)), list(range(0, 60, 6))])
def test_circle_2d_noisy_matches_newton(degrees) -> None:
    centre = (3.0, -4.0)
    points = radially_noisy_2d(centre, 50.0, degrees, 0.01, seed=7)
    fit = fit_circle_2d(points)
    reference = newton_centre(points, start=centre)
    assert close((fit.center_x, fit.center_y), reference, 1e-6)
    d = np.linalg.norm(np.asarray(points) - reference, axis=1)
    assert close(fit.radius, d.mean(), 1e-6)
    # The variance is the documented (1/n) sum (d_i - r)^2.
    assert math.isclose(fit.variance, float(np.mean((d - d.mean()) ** 2)), rel_tol=1e-6)
    assert fit.variance > 1e-6


def test_three_points_of_a_short_arc_where_gauss_newton_overshoots() -> None:
    """Three points 10 degrees apart whose Kasa start is far off: the plain Gauss-Newton
    step makes the cost worse, the Marquardt damping takes over and is relaxed again once
    steps succeed; the result is the circle through the three points."""
    points = [(50.0629, 0.0), (49.7439, 4.352), (49.5557, 8.738)]
    fit = fit_circle_2d(points)
    d = np.linalg.norm(np.asarray(points) - (fit.center_x, fit.center_y), axis=1)
    assert np.allclose(d, fit.radius, rtol=1e-12, atol=0.0)
    assert fit.variance < 1e-20


def test_geometric_circle_beats_kasa_on_a_partial_arc() -> None:
    centre = (3.0, -4.0)
    points = radially_noisy_2d(centre, 50.0, list(range(0, 46, 5)), 0.05, seed=3)
    fit = fit_circle_2d(points)
    geometric = (fit.center_x, fit.center_y)
    algebraic = kasa_centre(points)
    assert radial_ssr(points, geometric) < radial_ssr(points, algebraic) * (1 - 1e-6)
    # And it is a minimum: moving the centre a little in any direction costs more.
    best = radial_ssr(points, geometric)
    for angle in range(0, 360, 30):
        step = 1e-4 * np.array([math.cos(math.radians(angle)), math.sin(math.radians(angle))])
        assert radial_ssr(points, np.asarray(geometric) + step) > best


def test_sphere_noisy_matches_newton() -> None:
    directions = [(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (1, 1, 1),
                  (-1, 1, 0.5), (1, -1, 0.3), (-0.3, -1, 1), (0.5, 0.5, -1)]
    centre = (1.0, 2.0, -3.0)
    points = noisy(sphere_points(centre, 50.0, directions), 0.01, seed=11)
    fit = fit_sphere(points)
    reference = newton_centre(points, start=centre)
    assert close(fit.center, reference, 1e-6)
    d = np.linalg.norm(np.asarray(points) - reference, axis=1)
    assert close(fit.radius, d.mean(), 1e-6)
    assert math.isclose(fit.variance, float(np.mean((d - d.mean()) ** 2)), rel_tol=1e-6)


def test_plane_and_line_noisy_match_covariance_eigenvectors() -> None:
    normal = unit((1, -2, 4))
    u, v = plane_basis(normal)
    rng = np.random.default_rng(5)
    flat = [tuple(float(x) for x in np.array(CENTRE_3D) + a * u + b * v)
            for a, b in rng.uniform(-50, 50, (10, 2))]
    points = noisy(flat, 0.01, seed=6)
    p = np.asarray(points)
    centred = p - p.mean(axis=0)
    values, vectors = np.linalg.eigh(centred.T @ centred / len(p))  # ascending
    plane = fit_plane(points)
    assert close(plane.normal, oriented(vectors[:, 0]), 1e-6)
    assert close(plane.support, p.mean(axis=0))

    along = [tuple(float(x) for x in np.array([1.0, 2.0, 3.0]) + t * unit((2, 1, -1)))
             for t in np.linspace(0, 60, 10)]
    points = noisy(along, 0.01, seed=8)
    p = np.asarray(points)
    centred = p - p.mean(axis=0)
    values, vectors = np.linalg.eigh(centred.T @ centred / len(p))
    line = fit_line(points)
    first_to_last = vectors[:, 2] if (p[-1] - p[0]) @ vectors[:, 2] > 0 else -vectors[:, 2]
    assert close(line.direction, first_to_last, 1e-6)
    # Variance of the distances from the line = the two smaller covariance eigenvalues.
    assert math.isclose(line.variance, float(values[0] + values[1]), rel_tol=1e-6)
    assert line.variance > 1e-5


def test_circle_3d_noisy_matches_plane_then_newton() -> None:
    normal = (1, 2, 3)
    points = noisy(arc_3d(CENTRE_3D, 50.0, normal, range(0, 91, 10)), 0.01, seed=9)
    fit = fit_circle_3d(points)
    p = np.asarray(points)
    centroid = p.mean(axis=0)
    _, vectors = np.linalg.eigh((p - centroid).T @ (p - centroid))
    basis = vectors[:, 1:].T  # in-plane directions
    in_plane = (p - centroid) @ basis.T
    start = (np.asarray(CENTRE_3D) - centroid) @ basis.T
    centre_2d = newton_centre(in_plane, start=start)
    assert close(fit.normal, oriented(vectors[:, 0]), 1e-9)
    assert close(fit.center, centroid + centre_2d @ basis, 1e-6)
    d = np.linalg.norm(in_plane - centre_2d, axis=1)
    assert close(fit.radius, d.mean(), 1e-6)
    assert math.isclose(fit.radius_variance, float(np.mean((d - d.mean()) ** 2)), rel_tol=1e-6)
    # Same normal as the plane cycle for the same points.
    assert fit.normal == fit_plane(points).normal


# --- degenerate input --------------------------------------------------------------------

NAN = float("nan")
INF = float("inf")


@pytest.mark.parametrize(("fit", "points", "degeneracy"), [
    (fit_circle_2d, [(1.5, 2.0)] * 4, Degeneracy.IDENTICAL),
    (fit_circle_2d, [(0, 0), (1, 1), (2, 2)], Degeneracy.COLLINEAR),
    (fit_circle_2d, [(0, 0), (1, 1), (0, 0)], Degeneracy.COLLINEAR),
    (fit_circle_2d, [(0, 0), (1000, 1e-8), (2000, 0)], Degeneracy.COLLINEAR),
    (fit_plane, [(1, 2, 3)] * 3, Degeneracy.IDENTICAL),
    (fit_plane, [(0, 0, 0), (1, 1, 1), (2, 2, 2), (-3, -3, -3)], Degeneracy.COLLINEAR),
    (fit_circle_3d, [(1, 2, 3)] * 5, Degeneracy.IDENTICAL),
    (fit_circle_3d, [(0, 0, 0), (1, 2, 3), (2, 4, 6)], Degeneracy.COLLINEAR),
    (fit_sphere, [(4, 5, 6)] * 4, Degeneracy.IDENTICAL),
    (fit_sphere, [(1, 0, 0), (0, 1, 0), (-1, 0, 0), (0, -1, 0)], Degeneracy.COPLANAR),
    (fit_sphere, [(0, 0, 0), (1, 1, 0), (2, 2, 0), (3, 3, 0), (5, 5, 0)], Degeneracy.COLLINEAR),
    (fit_line, [(7, 8, 9)] * 2, Degeneracy.IDENTICAL),
    (fit_line, [(1e6, 0, 0), (1e6 + 1e-7, 0, 0)], Degeneracy.IDENTICAL),
    (fit_circle_2d, [(0, 0), (1, 0)], Degeneracy.TOO_FEW),
    (fit_plane, [(0, 0, 0), (1, 0, 0)], Degeneracy.TOO_FEW),
    (fit_circle_3d, [(0, 0, 0), (1, 0, 0)], Degeneracy.TOO_FEW),
    (fit_sphere, [(1, 0, 0), (0, 1, 0), (0, 0, 1)], Degeneracy.TOO_FEW),
    (fit_line, [(0, 0, 0)], Degeneracy.TOO_FEW),
    (fit_line, [], Degeneracy.TOO_FEW),
    (fit_circle_2d, [(0, 1), (1, NAN), (-1, 0)], Degeneracy.NOT_FINITE),
    (fit_plane, [(0, 0, 0), (1, 0, 0), (0, INF, 0)], Degeneracy.NOT_FINITE),
    (fit_line, [(NAN, 0, 0), (1, 0, 0)], Degeneracy.NOT_FINITE),
    (fit_sphere, [(1, 0, 0), (0, 1, 0), (0, 0, 1), (0, 0, -INF)], Degeneracy.NOT_FINITE),
    (fit_circle_3d, [(1, 0, 0), (0, 1, NAN), (0, 0, 1)], Degeneracy.NOT_FINITE),
], ids=lambda x: getattr(x, "__name__", None) or getattr(x, "name", None) or "")
def test_degenerate_input_raises(fit, points, degeneracy) -> None:
    with pytest.raises(FitError) as info:
        fit(points)
    assert info.value.degeneracy is degeneracy
    assert info.value.message == str(info.value)
    assert re.search(rf"\b{len(points)}\b", info.value.message)  # says how many points


@pytest.mark.parametrize(("fit", "dim"), [
    (fit_circle_2d, 2), (fit_plane, 3), (fit_line, 3), (fit_sphere, 3), (fit_circle_3d, 3),
])
def test_too_many_points(fit, dim) -> None:
    rng = np.random.default_rng(1)
    points = [tuple(float(x) for x in row) for row in rng.uniform(-1, 1, (MAX_POINTS + 1, dim))]
    with pytest.raises(FitError) as info:
        fit(points)
    assert info.value.degeneracy is Degeneracy.TOO_MANY
    assert "at most 10" in info.value.message and "11" in info.value.message
    fit(points[:MAX_POINTS])  # ten are fine


def test_messages_say_what_is_wrong() -> None:
    with pytest.raises(FitError) as info:
        fit_circle_2d([(0, 0), (1, 1), (2, 2)])
    assert info.value.message == "the 3 points are collinear: no circle passes through them"
    with pytest.raises(FitError) as info:
        fit_sphere([(0, 0, 0), (1, 0, 0)])
    assert info.value.message == "a sphere fit needs at least 4 points, got 2"
    with pytest.raises(FitError) as info:
        fit_sphere([(1, 0, 0), (0, 1, 0), (-1, 0, 0), (0, -1, 0)])
    assert "coplanar" in info.value.message and "4 points" in info.value.message
    with pytest.raises(FitError) as info:
        fit_line([(0, 0, 0), (0, NAN, 0)])
    assert "point 2 of 2" in info.value.message and "not finite" in info.value.message


def test_wrong_dimension_is_a_value_error() -> None:
    with pytest.raises(ValueError):
        fit_plane([(0, 0), (1, 0), (0, 1)])
    with pytest.raises(ValueError):
        fit_circle_2d([(0, 0, 0), (1, 0, 0), (0, 1, 0)])


# --- sign conventions --------------------------------------------------------------------


def test_plane_normal_is_plus_z_whatever_the_order() -> None:
    points = [(1, 0, 0), (0, 1, 0), (1, 1, 0)]
    assert close(fit_plane(points).normal, (0, 0, 1))
    assert close(fit_plane(points[::-1]).normal, (0, 0, 1))
    tilted = [(0, 0, 0), (1, 0, 1), (0, 1, -1), (1, 1, 0)]  # z = x - y
    expected = unit((-1, 1, 1))
    assert close(fit_plane(tilted).normal, expected)
    assert close(fit_plane(tilted[::-1]).normal, expected)


@pytest.mark.parametrize(("points", "normal"), [
    ([(0, 2, 0), (1, 2, 0), (0, 2, 1), (5, 2, -3)], (0, 1, 0)),        # y = 2
    ([(5, 2, -3), (0, 2, 1), (1, 2, 0), (0, 2, 0)], (0, 1, 0)),
    ([(-3, 0, 0), (-3, 1, 0), (-3, 0, 1)], (1, 0, 0)),                  # x = -3
    ([(-3, 0, 1), (-3, 1, 0), (-3, 0, 0)], (1, 0, 0)),
    ([(0, 0, 0), (1, 1, 0), (0, 0, 1)], tuple(unit((-1, 1, 0)))),       # vertical, diagonal
])
def test_vertical_plane_normal_plus_y_then_plus_x(points, normal) -> None:
    assert close(fit_plane(points).normal, normal)


def test_circle_3d_normal_independent_of_turning_direction() -> None:
    points = arc_3d((0, 0, 5), 2.0, (0, 0, 1), [0, 90, 180])
    assert close(fit_circle_3d(points).normal, (0, 0, 1))
    assert close(fit_circle_3d(points[::-1]).normal, (0, 0, 1))
    vertical = [(0, 1, 0), (0, 0, 1), (0, -1, 0)]  # circle in the YZ plane
    assert close(fit_circle_3d(vertical).normal, (1, 0, 0))


def test_line_direction_follows_point_order() -> None:
    points = [(0, 0, 0), (1, 0, 0), (2, 0, 0)]
    assert close(fit_line(points).direction, (1, 0, 0))
    assert close(fit_line(points[::-1]).direction, (-1, 0, 0))
    points = [(1, 1, 1), (2, 0, 1), (3, -1, 1)]
    assert close(fit_line(points).direction, unit((1, -1, 0)))
    assert close(fit_line(points[::-1]).direction, unit((-1, 1, 0)))


def test_line_direction_when_first_and_last_coincide_follows_normal_convention() -> None:
    points = [(0, 0, 0), (1, 1, 0), (0, 0, 0)]
    assert close(fit_line(points).direction, unit((1, 1, 0)))
    points = [(0, 0, 0), (-1, -1, -2), (0, 0, 0)]
    assert close(fit_line(points).direction, unit((1, 1, 2)))


# --- properties and speed ----------------------------------------------------------------


@st.composite
def circles(draw):
    centre = (draw(st.floats(-1000, 1000)), draw(st.floats(-1000, 1000)))
    radius = draw(st.floats(0.01, 1000))
    n = draw(st.integers(3, MAX_POINTS))
    start = draw(st.floats(0, 2 * math.pi))
    span = draw(st.floats(math.pi / 3, 2 * math.pi * (n - 1) / n))
    jitter = draw(st.lists(st.floats(-0.3, 0.3), min_size=n, max_size=n))
    # Evenly spread over the span, each point moved by at most 30 % of the spacing.
    angles = [start + span * (i + j) / (n - 1) for i, j in enumerate(jitter)]
    points = [(centre[0] + radius * math.cos(a), centre[1] + radius * math.sin(a))
              for a in angles]
    return centre, radius, points


@settings(max_examples=200, deadline=None)
@given(circles())
def test_points_on_a_circle_give_it_back(case) -> None:
    (cx, cy), radius, points = case
    fit = fit_circle_2d(points)
    assert abs(fit.center_x - cx) <= 1e-7 * radius
    assert abs(fit.center_y - cy) <= 1e-7 * radius
    assert abs(fit.radius - radius) <= 1e-7 * radius
    assert fit.variance <= (1e-7 * radius) ** 2


def test_each_fit_of_ten_points_is_well_under_a_millisecond() -> None:
    circle = radially_noisy_2d((3.0, -4.0), 50.0, list(range(0, 60, 6)), 0.01, seed=2)
    space = [(x, y, 0.1 * x) for x, y in circle]
    directions = [(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (1, 1, 1),
                  (-1, 1, 0.5), (1, -1, 0.3), (-0.3, -1, 1), (0.5, 0.5, -1)]
    sphere = noisy(sphere_points((1.0, 2.0, -3.0), 50.0, directions), 0.01, seed=4)
    for fit, points in [(fit_circle_2d, circle), (fit_plane, space), (fit_line, space),
                        (fit_sphere, sphere), (fit_circle_3d, space)]:
        best = math.inf
        for _ in range(20):  # the best of 20 runs: robust against a busy machine
            begin = time.perf_counter()
            fit(points)
            best = min(best, time.perf_counter() - begin)
        assert best < 1e-3, (fit.__name__, best)
