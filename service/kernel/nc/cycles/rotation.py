"""3x3 rotations for swivelling the machining coordinate system onto an inclined plane.

ISG's cycle SysPosRotationToPlane rotates the machining coordinate system (``#CS``)
onto an inclined plane given either by three reference points or by three angles.
This module is the geometry behind it: pure Python on tuples (no numpy) because the
decoder applies it to every block programmed in a rotated coordinate system, and for
3x3 matrices plain arithmetic is much faster than array set-up.

Conventions
-----------
* A ``Matrix`` is row-major, ``m[row][col]``. Its COLUMNS are the new frame's X, Y and
  Z axes expressed in the old frame, so ``apply(m, v)`` turns coordinates in the new
  frame into old-frame coordinates and ``apply_transposed(m, v)`` goes the other way.
* ``axis_rotation(axis, angle)`` follows the right-hand rule: a positive angle turns
  counter-clockwise seen from the + end of the axis looking toward the origin
  (90 degrees about Z maps X onto Y).
* The angles are always ``a`` about X, ``b`` about Y and ``c`` about Z (degrees),
  whatever the rotation order (ISG's @P15, @P16, @P17).
* A ``RotationOrder`` (ISG's @P19) lists the axes in the order the rotations are
  APPLIED. The default ``ZYX`` (6) is also the order of ISG's ``#CS ON[x,y,z,a,b,c]``.
* Intrinsic (ISG @P18=1, "projection angle", the default): each rotation turns about
  the axis of the already rotated frame. Intrinsic ``ZYX`` turns by c about Z, then by
  b about the new Y', then by a about the newest X'':
  ``R = Rz(c) @ Ry(b) @ Rx(a)`` -- the factors in the order's sequence.
* Extrinsic (ISG @P18=2, "spatial angle"): each rotation turns about the fixed axes of
  the original frame. Extrinsic ``ZYX`` turns about the fixed Z, then the fixed Y, then
  the fixed X: ``R = Rx(a) @ Ry(b) @ Rz(c)`` -- the factors in reversed sequence.
  Hence intrinsic order O equals extrinsic order reversed(O) with the same angles.
* ``angles_from_rotation`` is the inverse of ``rotation_from_angles``: all angles lie in
  (-180, 180], the middle rotation of the order in [-90, 90]. At gimbal lock (middle
  angle +-90 degrees) only a sum or difference of the other two angles is defined; the
  angle of the RIGHTMOST factor of the product above is then set to 0, i.e. the
  last-applied rotation for intrinsic orders, the first-applied one for extrinsic.
* ``rotation_from_points`` (ISG's definition): new X parallel to point 1 -> point 2,
  new Z normal to the plane of the three points with a positive Z component, and
  ``Y = Z x X``. For a vertical plane (normal Z component 0 to 1e-12) the normal is
  chosen with a positive Y component, and if that is 0 too, a positive X component.
"""

from __future__ import annotations

import enum
import math

Vector = tuple[float, float, float]
Matrix = tuple[Vector, Vector, Vector]

IDENTITY: Matrix = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))

# Relative tolerance below which reference points count as coinciding / collinear.
_POINT_TOLERANCE = 1e-9
# Normal components this close to 0 (the normal is a unit vector) count as 0 when the
# orientation of the plane normal is chosen.
_ORIENTATION_TOLERANCE = 1e-12
# |cos(middle angle)| below this is treated as gimbal lock by angles_from_rotation.
_GIMBAL_TOLERANCE = 1e-12

_AXIS_INDEX = {"X": 0, "Y": 1, "Z": 2}
# cos, sin of k * 90 degrees: exact, so that e.g. a 90 degree #CS gives clean zeros
# instead of 6e-17 noise in every transformed position.
_QUARTER_TURNS = ((1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0))


class RotationOrder(enum.IntEnum):
    """Sequence in which the rotations about X, Y, Z are applied (ISG @P19)."""

    XYZ = 1
    XZY = 2
    YXZ = 3
    YZX = 4
    ZXY = 5
    ZYX = 6


class RotationError(Exception):
    """The rotation cannot be built, e.g. the reference points define no plane."""

    def __init__(self, message: str) -> None:
        super().__init__(message)
        self.message = message


def _cos_sin(angle_deg: float) -> tuple[float, float]:
    if angle_deg % 90.0 == 0.0:
        return _QUARTER_TURNS[int(angle_deg // 90.0) % 4]
    rad = math.radians(angle_deg)
    return math.cos(rad), math.sin(rad)


def axis_rotation(axis: str, angle_deg: float) -> Matrix:
    """Rotation by ``angle_deg`` about the X, Y or Z axis (right-hand rule)."""
    c, s = _cos_sin(angle_deg)
    if axis == "X":
        return ((1.0, 0.0, 0.0), (0.0, c, -s), (0.0, s, c))
    if axis == "Y":
        return ((c, 0.0, s), (0.0, 1.0, 0.0), (-s, 0.0, c))
    if axis == "Z":
        return ((c, -s, 0.0), (s, c, 0.0), (0.0, 0.0, 1.0))
    raise ValueError(f"rotation axis must be 'X', 'Y' or 'Z', not {axis!r}")


def multiply(m: Matrix, n: Matrix) -> Matrix:
    """The matrix product ``m @ n``."""
    (m00, m01, m02), (m10, m11, m12), (m20, m21, m22) = m
    (n00, n01, n02), (n10, n11, n12), (n20, n21, n22) = n
    return (
        (m00 * n00 + m01 * n10 + m02 * n20,
         m00 * n01 + m01 * n11 + m02 * n21,
         m00 * n02 + m01 * n12 + m02 * n22),
        (m10 * n00 + m11 * n10 + m12 * n20,
         m10 * n01 + m11 * n11 + m12 * n21,
         m10 * n02 + m11 * n12 + m12 * n22),
        (m20 * n00 + m21 * n10 + m22 * n20,
         m20 * n01 + m21 * n11 + m22 * n21,
         m20 * n02 + m21 * n12 + m22 * n22),
    )


def transpose(m: Matrix) -> Matrix:
    """The transpose of ``m`` (its inverse when ``m`` is a rotation)."""
    (m00, m01, m02), (m10, m11, m12), (m20, m21, m22) = m
    return ((m00, m10, m20), (m01, m11, m21), (m02, m12, m22))


def apply(m: Matrix, v: Vector) -> Vector:
    """``m @ v``: new-frame coordinates of ``v`` turned into old-frame coordinates."""
    x, y, z = v
    (m00, m01, m02), (m10, m11, m12), (m20, m21, m22) = m
    return (m00 * x + m01 * y + m02 * z,
            m10 * x + m11 * y + m12 * z,
            m20 * x + m21 * y + m22 * z)


def apply_transposed(m: Matrix, v: Vector) -> Vector:
    """``m.T @ v``: old-frame coordinates of ``v`` turned into new-frame coordinates."""
    x, y, z = v
    (m00, m01, m02), (m10, m11, m12), (m20, m21, m22) = m
    return (m00 * x + m10 * y + m20 * z,
            m01 * x + m11 * y + m21 * z,
            m02 * x + m12 * y + m22 * z)


def is_rotation(m: Matrix, tol: float = 1e-9) -> bool:
    """True when ``m`` is orthonormal with determinant +1 (each to ``tol``)."""
    p = multiply(m, transpose(m))
    for i in range(3):
        for j in range(3):
            # "not <=" so that NaN entries make the matrix no rotation
            if not abs(p[i][j] - (1.0 if i == j else 0.0)) <= tol:
                return False
    (m00, m01, m02), (m10, m11, m12), (m20, m21, m22) = m
    det = (m00 * (m11 * m22 - m12 * m21)
           - m01 * (m10 * m22 - m12 * m20)
           + m02 * (m10 * m21 - m11 * m20))
    return abs(det - 1.0) <= tol


def _axis_indices(order: RotationOrder, intrinsic: bool) -> tuple[int, int, int]:
    first, second, third = (_AXIS_INDEX[name] for name in order.name)
    return (first, second, third) if intrinsic else (third, second, first)


# Axis indices of the factors of R from left to right, per (order, intrinsic): intrinsic
# rotations multiply in the order's sequence, extrinsic ones in reverse. A table because
# this is looked up for every rotation built.
_FACTOR_AXES: dict[tuple[int, bool], tuple[int, int, int]] = {
    (order, intrinsic): _axis_indices(order, intrinsic)
    for order in RotationOrder
    for intrinsic in (True, False)
}


def _factor_axes(order: RotationOrder, intrinsic: bool) -> tuple[int, int, int]:
    return _FACTOR_AXES[(RotationOrder(order), bool(intrinsic))]


def rotation_from_angles(a_deg: float, b_deg: float, c_deg: float,
                         order: RotationOrder = RotationOrder.ZYX,
                         intrinsic: bool = True) -> Matrix:
    """Rotation turning by ``a`` about X, ``b`` about Y, ``c`` about Z in ``order``.

    Intrinsic: ``R = R1 @ R2 @ R3`` with R1..R3 in the order's sequence; extrinsic:
    the reversed product (see the module docstring).
    """
    angles = (a_deg, b_deg, c_deg)
    i, j, k = _factor_axes(order, intrinsic)
    return multiply(multiply(axis_rotation("XYZ"[i], angles[i]),
                             axis_rotation("XYZ"[j], angles[j])),
                    axis_rotation("XYZ"[k], angles[k]))


def _degrees(rad: float) -> float:
    deg = math.degrees(rad)
    if deg <= -180.0:  # atan2 may return -pi; the documented range is (-180, 180]
        deg += 360.0
    return deg + 0.0  # turns -0.0 into 0.0


def angles_from_rotation(m: Matrix, order: RotationOrder = RotationOrder.ZYX,
                         intrinsic: bool = True) -> tuple[float, float, float]:
    """The angles ``(a, b, c)`` in degrees with ``rotation_from_angles(a, b, c, ...) == m``.

    Angles lie in (-180, 180]; the middle rotation of the order in [-90, 90]. At gimbal
    lock the angle of the rightmost factor (last applied intrinsic / first applied
    extrinsic rotation) is 0.
    """
    # Solve m = R_i(al) @ R_j(be) @ R_k(ga) for the left-to-right factor axes i, j, k.
    # e = +1 when (i, j, k) is cyclic (XYZ, YZX, ZXY), -1 otherwise; it fixes the signs.
    i, j, k = _factor_axes(order, intrinsic)
    e = 1.0 if (j - i) % 3 == 1 else -1.0
    cos_be = math.hypot(m[i][i], m[i][j])
    be = math.atan2(e * m[i][k], cos_be)
    if cos_be > _GIMBAL_TOLERANCE:
        al = math.atan2(-e * m[j][k], m[k][k])
        ga = math.atan2(-e * m[i][j], m[i][i])
    else:
        # m = R_i(al) @ R_j(+-90): R_j keeps axis j, so column j of m is R_i(al) e_j.
        al = math.atan2(e * m[k][j], m[j][j])
        ga = 0.0
    angles = [0.0, 0.0, 0.0]
    angles[i], angles[j], angles[k] = _degrees(al), _degrees(be), _degrees(ga)
    return angles[0], angles[1], angles[2]


def _sub(p: Vector, q: Vector) -> Vector:
    return (p[0] - q[0], p[1] - q[1], p[2] - q[2])


def _cross(u: Vector, v: Vector) -> Vector:
    return (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])


def _norm(v: Vector) -> float:
    return math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])


def rotation_from_points(p1: Vector, p2: Vector, p3: Vector) -> Matrix:
    """Rotation onto the plane through three reference points (ISG's definition).

    New X: parallel to ``p2 - p1``. New Z: the plane normal with a positive Z component
    (vertical plane: positive Y, then positive X). New Y: ``Z x X``. Raises
    ``RotationError`` when points 1 and 2 coincide or all three are collinear, both
    judged relative to the longest edge of the triangle.
    """
    x = _sub(p2, p1)
    v = _sub(p3, p1)
    x_len = _norm(x)
    scale = max(x_len, _norm(v), _norm(_sub(p3, p2)))
    if x_len <= _POINT_TOLERANCE * scale or scale == 0.0:
        raise RotationError("reference points 1 and 2 coincide: the X axis of the plane "
                            "is undefined")
    n = _cross(x, v)
    n_len = _norm(n)
    # |n| is twice the triangle's area: compare with the longest edge squared so that
    # the test is independent of the size of the triangle and of the corner used.
    if n_len <= _POINT_TOLERANCE * scale * scale:
        raise RotationError("the three reference points are collinear: they define no "
                            "plane")
    zx, zy, zz = n[0] / n_len, n[1] / n_len, n[2] / n_len
    if abs(zz) > _ORIENTATION_TOLERANCE:
        flip = zz < 0.0
    elif abs(zy) > _ORIENTATION_TOLERANCE:
        flip = zy < 0.0
    else:
        flip = zx < 0.0
    if flip:
        zx, zy, zz = -zx, -zy, -zz
    xx, xy, xz = x[0] / x_len, x[1] / x_len, x[2] / x_len
    yx, yy, yz = _cross((zx, zy, zz), (xx, xy, xz))
    return ((xx, yx, zx), (xy, yy, zy), (xz, yz, zz))
