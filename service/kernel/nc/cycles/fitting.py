"""Least-squares fits of the ISG calculation cycles (SysCalcCircle, SysCalcPlane,
SysCalcLine, SysCalcSphere, SysCalcPlaneCircle) to 2..10 measured points.

The cycles promise "the most probable result from measured points". For a measuring
user that is the *geometric* least-squares fit: the shape that minimises the sum of
the squared orthogonal distances of the points from it.

- Plane and line (``fit_plane``, ``fit_line``): total least squares by an SVD of the
  points minus their centroid. This is the exact geometric fit: the plane normal is the
  right singular vector of the smallest singular value, the line direction the one of
  the largest; both pass through the centroid, which is the returned ``support``.
- Circle in XY and sphere (``fit_circle_2d``, ``fit_sphere``): the algebraic (Kasa) fit
  ``|p|^2 = 2 c.p + k`` gives the start value; Levenberg-Marquardt on the geometric
  residuals ``|p_i - c| - r`` then moves to the geometric optimum. The Kasa fit alone
  is not enough: with points on a partial arc it is biased toward smaller radii. At the
  optimum ``r`` is the mean distance of the points from the centre, so the iteration
  runs on the centre only (``r`` eliminated as that mean). It stops when the remaining
  change of the centre is below 1e-15 of the point spread (or has shrunk to rounding
  noise), after at most 100 iterations; measured points need 2 to 4. Very noisy points
  that hardly curve can run into the cap: their best circle is huge and ill-defined.
- Circle in space (``fit_circle_3d``): the plane is fitted as by ``fit_plane``, the
  points are projected into an orthonormal basis of that plane, the 2D geometric circle
  is fitted there and its centre is mapped back to 3D. This is the plane-then-circle
  fit, not the full 3D orthogonal-distance circle fit: both agree for points that lie
  on a circle, and this way the normal is identical to the one SysCalcPlane returns
  for the same points.

Variances (``variance`` / ``radius_variance``), with ``n`` the number of points:

- circle, sphere, circle in space: ``(1/n) * sum (d_i - r)^2``, ``d_i`` the distance of
  point ``i`` from the centre (for the circle in space the in-plane distance, i.e. of
  the point projected into the fitted plane);
- line: ``(1/n) * sum e_i^2``, ``e_i`` the distance of point ``i`` from the line.

Exact points give 0 up to rounding (about 1e-20 and never negative).

Sign conventions:

- A plane or circle normal is a unit vector with positive Z component; if Z is 0 (to
  1e-12, the normal being a unit vector this is relative), with positive Y; if Y is 0
  too, with positive X. The XY plane gives (0, 0, 1) whatever the point order.
- A line direction is a unit vector pointing from the projection of the first point on
  the line toward the projection of the last point (points along +X give (1, 0, 0)).
  If those projections coincide (first and last point at the same place along the
  line), the direction follows the normal convention above.

Degenerate input raises ``FitError`` (with a ``Degeneracy``), never returns a number:
wrong point count, NaN or infinite coordinates, all points identical, collinear points
for a circle, plane or circle in space, coplanar (or collinear) points for a sphere.
The tests are scale-relative: the points are identical when their largest distance from
the centroid is below ``1e-12 * (1 + max |coordinate|)``; collinear / coplanar when the
second / third singular value of the centred points is below ``1e-9`` times the largest.
"""

from __future__ import annotations

import enum
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

MAX_POINTS = 10

_IDENTICAL_TOLERANCE = 1e-12  # spread relative to 1 + the largest coordinate
_RANK_TOLERANCE = 1e-9  # singular value relative to the largest one
_SIGN_TOLERANCE = 1e-12  # a unit-vector component this small counts as 0
_STEP_TOLERANCE = 1e-15  # converged step relative to 1 + |centre| (scaled coordinates)
_STALL_SIZE = 1e-10  # Gauss-Newton steps this small (relative) that stop shrinking: done
_MAX_ITERATIONS = 100

Vector = tuple[float, float, float]


class Degeneracy(enum.Enum):
    """Why no fit is defined for the given points."""

    TOO_FEW = "too few points"
    TOO_MANY = "too many points"
    IDENTICAL = "all points identical"
    COLLINEAR = "points collinear"
    COPLANAR = "points coplanar"
    NOT_FINITE = "coordinate not finite"


class FitError(Exception):
    """The points do not define the requested shape.

    ``degeneracy`` says what kind of problem it is, ``message`` says what is wrong in
    words, including the number of points.
    """

    def __init__(self, degeneracy: Degeneracy, message: str) -> None:
        super().__init__(message)
        self.degeneracy = degeneracy
        self.message = message


@dataclass(frozen=True, slots=True)
class CircleFit:
    """A circle in the XY plane: centre, radius and the variance of the radial residuals."""

    center_x: float
    center_y: float
    radius: float
    variance: float


@dataclass(frozen=True, slots=True)
class PlaneFit:
    """A plane: unit ``normal`` (sign convention in the module docstring), ``support`` =
    the centroid of the points."""

    normal: Vector
    support: Vector


@dataclass(frozen=True, slots=True)
class LineFit:
    """A line: unit ``direction`` (first toward last point), ``support`` = the centroid,
    ``variance`` of the distances of the points from the line."""

    direction: Vector
    support: Vector
    variance: float


@dataclass(frozen=True, slots=True)
class SphereFit:
    """A sphere: centre, radius and the variance of the radial residuals."""

    center: Vector
    radius: float
    variance: float


@dataclass(frozen=True, slots=True)
class Circle3dFit:
    """A circle in space: centre, radius, unit normal of its plane (as ``fit_plane``) and
    the variance of the in-plane radial residuals."""

    center: Vector
    radius: float
    normal: Vector
    radius_variance: float


# --- public fits -------------------------------------------------------------------------


def fit_circle_2d(points: Sequence[Sequence[float]]) -> CircleFit:
    """Geometric least-squares circle through 3..10 points in the XY plane.

    Raises ``FitError`` for a wrong count, NaN/inf, identical or collinear points.
    """
    p = _checked(points, dim=2, minimum=3, shape="circle")
    spread, singular, _ = _centred_svd(p)
    _reject_identical(p, spread, "circle")
    if singular[1] <= _RANK_TOLERANCE * singular[0]:
        raise _collinear(len(p), "no circle passes through them")
    centre, radius, variance = _fit_round(p, spread, "circle")
    return CircleFit(float(centre[0]) + 0.0, float(centre[1]) + 0.0, radius, variance)


def fit_plane(points: Sequence[Sequence[float]]) -> PlaneFit:
    """Total least-squares plane through 3..10 points (normal +Z, else +Y, else +X).

    Raises ``FitError`` for a wrong count, NaN/inf, identical or collinear points.
    """
    p = _checked(points, dim=3, minimum=3, shape="plane")
    centroid, basis = _plane_of(p, "plane", "no unique plane passes through them")
    return PlaneFit(normal=_vector(_oriented(basis[2])), support=_vector(centroid))


def fit_line(points: Sequence[Sequence[float]]) -> LineFit:
    """Total least-squares line through 2..10 points, directed from first toward last.

    Raises ``FitError`` for a wrong count, NaN/inf or identical points.
    """
    p = _checked(points, dim=3, minimum=2, shape="line")
    spread, _, basis = _centred_svd(p)
    _reject_identical(p, spread, "line")
    centroid = p.mean(axis=0)
    centred = p - centroid
    direction = basis[0]
    along = centred @ direction
    # Which way the first-to-last projection goes; sign-less when they coincide.
    travel = along[-1] - along[0]
    if abs(travel) > _SIGN_TOLERANCE * spread:
        direction = direction if travel > 0 else -direction
    else:
        direction = _oriented(direction)
    off_line = centred - np.outer(along, direction)
    variance = float(np.mean(np.einsum("ij,ij->i", off_line, off_line)))
    return LineFit(direction=_vector(direction), support=_vector(centroid), variance=variance)


def fit_sphere(points: Sequence[Sequence[float]]) -> SphereFit:
    """Geometric least-squares sphere through 4..10 points.

    Raises ``FitError`` for a wrong count, NaN/inf, identical, collinear or coplanar
    points.
    """
    p = _checked(points, dim=3, minimum=4, shape="sphere")
    spread, singular, _ = _centred_svd(p)
    _reject_identical(p, spread, "sphere")
    n = len(p)
    if singular[1] <= _RANK_TOLERANCE * singular[0]:
        raise _collinear(n, "no unique sphere passes through them")
    if singular[2] <= _RANK_TOLERANCE * singular[0]:
        raise FitError(
            Degeneracy.COPLANAR,
            f"the {n} points are coplanar: no unique sphere passes through them",
        )
    centre, radius, variance = _fit_round(p, spread, "sphere")
    return SphereFit(center=_vector(centre), radius=radius, variance=variance)


def fit_circle_3d(points: Sequence[Sequence[float]]) -> Circle3dFit:
    """Circle in space through 3..10 points: plane fit, then 2D circle fit in that plane.

    The normal is the one ``fit_plane`` returns for the same points. Raises ``FitError``
    for a wrong count, NaN/inf, identical or collinear points.
    """
    p = _checked(points, dim=3, minimum=3, shape="circle")
    centroid, basis = _plane_of(p, "circle", "no circle passes through them")
    # In-plane coordinates along the two largest principal directions; the circle fit is
    # invariant to how that basis is rotated or mirrored inside the plane.
    in_plane = (p - centroid) @ basis[:2].T
    spread = float(np.max(np.linalg.norm(in_plane, axis=1)))
    centre_2d, radius, variance = _fit_round(in_plane, spread, "circle")
    centre = centroid + centre_2d @ basis[:2]
    return Circle3dFit(
        center=_vector(centre),
        radius=radius,
        normal=_vector(_oriented(basis[2])),
        radius_variance=variance,
    )


# --- input checks ------------------------------------------------------------------------


def _checked(points: Sequence[Sequence[float]], *, dim: int, minimum: int,
             shape: str) -> np.ndarray:
    """The points as an (n, dim) float array; FitError for a wrong count or NaN/inf."""
    n = len(points)
    if n < minimum:
        raise FitError(
            Degeneracy.TOO_FEW, f"a {shape} fit needs at least {minimum} points, got {n}"
        )
    if n > MAX_POINTS:
        raise FitError(
            Degeneracy.TOO_MANY, f"a {shape} fit takes at most {MAX_POINTS} points, got {n}"
        )
    try:
        p = np.array(points, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"every point must have {dim} numeric coordinates") from exc
    if p.ndim != 2 or p.shape[1] != dim:
        raise ValueError(f"every point must have {dim} coordinates")
    finite = np.isfinite(p).all(axis=1)
    if not finite.all():
        bad = int(np.argmin(finite))
        raise FitError(
            Degeneracy.NOT_FINITE,
            f"point {bad + 1} of {n} has a coordinate that is not finite "
            f"{tuple(float(v) for v in p[bad])}: no {shape} can be fitted",
        )
    return p


def _centred_svd(p: np.ndarray) -> tuple[float, np.ndarray, np.ndarray]:
    """(largest distance from the centroid, singular values, right singular vectors)."""
    centred = p - p.mean(axis=0)
    spread = float(np.max(np.linalg.norm(centred, axis=1)))
    _, singular, basis = np.linalg.svd(centred, full_matrices=False)
    if basis.shape[0] < p.shape[1]:
        # Fewer points than dimensions (a line through 2 points): complete the basis so
        # callers can always index it; the missing singular values are 0.
        _, _, basis = np.linalg.svd(centred, full_matrices=True)
        singular = np.concatenate([singular, np.zeros(p.shape[1] - len(singular))])
    return spread, singular, basis


def _reject_identical(p: np.ndarray, spread: float, shape: str) -> None:
    # Relative to the coordinates: points 1e-9 apart are distinct near 0, equal near 1e6.
    if spread <= _IDENTICAL_TOLERANCE * (1.0 + float(np.max(np.abs(p)))):
        raise FitError(
            Degeneracy.IDENTICAL,
            f"all {len(p)} points are identical: no {shape} is defined by a single point",
        )


def _collinear(n: int, consequence: str) -> FitError:
    return FitError(Degeneracy.COLLINEAR, f"the {n} points are collinear: {consequence}")


def _plane_of(p: np.ndarray, shape: str, consequence: str) -> tuple[np.ndarray, np.ndarray]:
    """(centroid, right singular vectors) of non-degenerate points; row 2 is the normal."""
    spread, singular, basis = _centred_svd(p)
    _reject_identical(p, spread, shape)
    if singular[1] <= _RANK_TOLERANCE * singular[0]:
        raise _collinear(len(p), consequence)
    return p.mean(axis=0), basis


# --- circle and sphere -------------------------------------------------------------------


def _fit_round(p: np.ndarray, spread: float, shape: str) -> tuple[np.ndarray, float, float]:
    """(centre, radius, variance) of the geometric circle (2D) or sphere (3D) fit."""
    # Work on points centred at their centroid and scaled to unit spread: the iteration
    # and its tolerances then do not depend on where the part is or how large it is.
    centroid = p.mean(axis=0)
    q = (p - centroid) / spread
    centre = centroid + spread * _geometric_centre(q)
    distance = np.linalg.norm(p - centre, axis=1)
    radius = float(distance.mean())
    variance = float(np.mean((distance - radius) ** 2))
    if not (math.isfinite(radius) and np.isfinite(centre).all()):
        # Points so close to a line (plane) that the best fit runs away to infinity.
        raise _collinear(len(p), f"no {shape} can be fitted")
    return centre, radius, variance


def _geometric_centre(q: np.ndarray) -> np.ndarray:
    """Levenberg-Marquardt from the Kasa centre on the residuals |q_i - c| - mean_j |q_j - c|.

    ``q`` is centred and scaled to unit spread, so tolerances are relative. Done when the
    remaining error is below ``_STEP_TOLERANCE * (1 + |c|)``: the step itself, or for a
    Gauss-Newton step that shrank by ``ratio`` from the previous one (linear convergence)
    the rest of the geometric series, ``step * ratio / (1 - ratio)``. Also done when
    tiny Gauss-Newton steps (``_STALL_SIZE``) stop shrinking: they are then rounding
    noise, and more iterations only walk around in it.
    """
    dim = q.shape[1]
    centre = _kasa_centre(q)
    cost, residual, jacobian = _residuals(q, centre)
    damping = 0.0  # start as plain Gauss-Newton, which converges fast from the Kasa centre
    previous = math.inf  # size of the previous accepted Gauss-Newton step
    for _ in range(_MAX_ITERATIONS):
        if cost == 0.0:
            break
        system = jacobian.T @ jacobian
        if damping:
            # Marquardt: scale by the diagonal; the tiny floor keeps the matrix regular.
            system[np.diag_indices(dim)] *= 1.0 + damping
            system[np.diag_indices(dim)] += 1e-300
        try:
            step = np.linalg.solve(system, -(jacobian.T @ residual))
        except np.linalg.LinAlgError:
            damping = max(10.0 * damping, 1e-6)
            continue
        size = math.sqrt(float(step @ step))
        reach = 1.0 + math.sqrt(float(centre @ centre))  # what rounding is relative to
        tolerance = _STEP_TOLERANCE * reach
        trial = centre + step
        trial_cost, trial_residual, trial_jacobian = _residuals(q, trial)
        # Near the optimum the cost only changes in its last digits: a step that does not
        # make it worse beyond rounding is as good, and the Gauss-Newton fixed point
        # (gradient 0) is more accurate than any comparison of costs.
        if trial_cost <= cost * (1.0 + 1e-12) + 1e-30:
            centre, cost, residual, jacobian = trial, trial_cost, trial_residual, trial_jacobian
            if damping == 0.0:
                ratio = size / previous
                remaining = size * ratio / (1.0 - ratio) if 0.0 < ratio < 1.0 else math.inf
                stalled = ratio > 0.5 and size <= _STALL_SIZE * reach
                if size <= tolerance or remaining <= tolerance or stalled:
                    break
                previous = size
            else:
                previous = math.inf
                damping = 0.0 if damping < 1e-9 else damping / 10.0
        else:
            # Overshooting far from the optimum: fall back toward gradient descent.
            if size <= tolerance:
                break
            damping = max(10.0 * damping, 1e-6)
            previous = math.inf
    return centre


def _kasa_centre(q: np.ndarray) -> np.ndarray:
    """Algebraic fit |q|^2 = 2 c.q + k, linear in (c, k): the start of the iteration."""
    n, dim = q.shape
    design = np.column_stack([2.0 * q, np.ones(n)])
    solution, *_ = np.linalg.lstsq(design, np.einsum("ij,ij->i", q, q), rcond=None)
    centre: np.ndarray = solution[:dim]  # numpy's stubs type the slice as Any
    return centre


def _residuals(q: np.ndarray, centre: np.ndarray) -> tuple[float, np.ndarray, np.ndarray]:
    """(sum of squares, residuals d_i - mean d, Jacobian w.r.t. the centre).

    The radius is eliminated as the mean distance (its optimum for a fixed centre), so
    d(d_i - mean d)/dc = -(u_i - mean u) with u_i the unit vector from c toward q_i.
    """
    # sum() / n instead of mean(): the same number, a fraction of numpy's call overhead.
    n = len(q)
    offset = q - centre
    distance = np.sqrt(np.einsum("ij,ij->i", offset, offset))
    residual = distance - distance.sum() / n
    # A point exactly at the centre has no direction; it contributes no gradient.
    unit = offset / np.where(distance > 0.0, distance, 1.0)[:, None]
    jacobian = unit.sum(axis=0) / n - unit
    return float(residual @ residual), residual, jacobian


# --- results -----------------------------------------------------------------------------


def _oriented(normal: np.ndarray) -> np.ndarray:
    """The unit vector with the documented sign: +Z, else +Y, else +X."""
    for axis in (2, 1, 0):
        if abs(normal[axis]) > _SIGN_TOLERANCE:
            return normal if normal[axis] > 0.0 else -normal
    return normal


def _vector(v: np.ndarray) -> Vector:
    # Plain floats: results are stored and compared outside numpy. Adding 0.0 turns a
    # -0.0 (from flipping a sign) into 0.0.
    return (float(v[0]) + 0.0, float(v[1]) + 0.0, float(v[2]) + 0.0)
