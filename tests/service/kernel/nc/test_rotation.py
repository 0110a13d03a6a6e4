"""Rotations of the machining coordinate system onto an inclined plane (SysPosRotationToPlane)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given
from hypothesis import strategies as st

from cnc_objects.service.kernel.nc.cycles.rotation import (
    IDENTITY,
    Matrix,
    RotationError,
    RotationOrder,
    Vector,
    angles_from_rotation,
    apply,
    apply_transposed,
    axis_rotation,
    is_rotation,
    multiply,
    rotation_from_angles,
    rotation_from_points,
    transpose,
)

ORDERS = list(RotationOrder)
COMBINATIONS = [(order, intrinsic) for order in ORDERS for intrinsic in (True, False)]
COMBINATION_IDS = [f"{o.name}-{'intrinsic' if i else 'extrinsic'}" for o, i in COMBINATIONS]
ANGLE_SETS = [(0.0, 0.0, 0.0), (60.0, 0.0, 90.0), (10.0, 20.0, 30.0),
              (-35.5, 72.25, 161.0), (170.0, -80.0, -120.0)]
R3 = math.sqrt(3.0) / 2.0


def close(m, expected, tol: float = 1e-12) -> bool:
    """Element-wise closeness of matrices or vectors given as nested sequences."""
    return np.allclose(np.array(m, dtype=float), np.array(expected, dtype=float),
                       rtol=0.0, atol=tol)


def column(m: Matrix, index: int) -> Vector:
    return (m[0][index], m[1][index], m[2][index])


def angle_difference(x: float, y: float) -> float:
    """|x - y| modulo 360 degrees (179.99999 and -180 are neighbours)."""
    d = (x - y) % 360.0
    return min(d, 360.0 - d)


# ---- independent references, written with numpy from the textbook definitions


def elementary(axis: str, angle_deg: float) -> np.ndarray:
    c, s = math.cos(math.radians(angle_deg)), math.sin(math.radians(angle_deg))
    return {
        "X": np.array([[1, 0, 0], [0, c, -s], [0, s, c]]),
        "Y": np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]]),
        "Z": np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]]),
    }[axis]


def rodrigues(axis: np.ndarray, angle_deg: float) -> np.ndarray:
    """Rotation by angle about an arbitrary unit axis."""
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    t = math.radians(angle_deg)
    return np.eye(3) + math.sin(t) * k + (1 - math.cos(t)) * (k @ k)


def moving_frame(angles: tuple[float, float, float], order: RotationOrder,
                 intrinsic: bool) -> np.ndarray:
    """Turn a frame step by step like the machine: about its own current axis
    (intrinsic) or about the fixed world axis (extrinsic). Columns are the frame axes."""
    frame = np.eye(3)
    for name in order.name:
        index = "XYZ".index(name)
        axis = frame[:, index] if intrinsic else np.eye(3)[:, index]
        frame = rodrigues(axis, angles[index]) @ frame
    return frame


# ---------------------------------------------------------------- elementary rotations


@pytest.mark.parametrize("axis, vector, image", [
    ("X", (1, 0, 0), (1, 0, 0)), ("X", (0, 1, 0), (0, 0, 1)), ("X", (0, 0, 1), (0, -1, 0)),
    ("Y", (0, 1, 0), (0, 1, 0)), ("Y", (0, 0, 1), (1, 0, 0)), ("Y", (1, 0, 0), (0, 0, -1)),
    ("Z", (0, 0, 1), (0, 0, 1)), ("Z", (1, 0, 0), (0, 1, 0)), ("Z", (0, 1, 0), (-1, 0, 0)),
])
def test_a_quarter_turn_maps_unit_vectors_counter_clockwise(axis, vector, image) -> None:
    assert close(apply(axis_rotation(axis, 90.0), vector), image)


def test_quarter_turns_are_exact_so_positions_carry_no_noise() -> None:
    assert axis_rotation("Z", 90.0) == ((0.0, -1.0, 0.0), (1.0, 0.0, 0.0), (0.0, 0.0, 1.0))
    assert axis_rotation("X", -90.0) == ((1.0, 0.0, 0.0), (0.0, 0.0, 1.0), (0.0, -1.0, 0.0))
    assert axis_rotation("Y", 540.0) == ((-1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, -1.0))


def test_a_general_angle_turns_by_that_angle() -> None:
    assert close(apply(axis_rotation("Z", 30.0), (1, 0, 0)), (R3, 0.5, 0))
    assert close(apply(axis_rotation("X", 60.0), (0, 1, 0)), (0, 0.5, R3))
    assert close(apply(axis_rotation("Y", -45.0), (0, 0, 1)),
                 (-math.sqrt(0.5), 0, math.sqrt(0.5)))


def test_an_unknown_axis_is_rejected() -> None:
    with pytest.raises(ValueError, match="'X', 'Y' or 'Z'"):
        axis_rotation("W", 10.0)


# ---------------------------------------------------------------- angles -> matrix


def test_default_is_intrinsic_zyx_as_spelled_out() -> None:
    a, b, c = 10.0, 20.0, 30.0
    rz, ry, rx = elementary("Z", c), elementary("Y", b), elementary("X", a)
    assert close(rotation_from_angles(a, b, c), rz @ ry @ rx)
    assert close(rotation_from_angles(a, b, c, RotationOrder.ZYX, intrinsic=False),
                 rx @ ry @ rz)


@pytest.mark.parametrize("order, intrinsic", COMBINATIONS, ids=COMBINATION_IDS)
@pytest.mark.parametrize("angles", ANGLE_SETS)
def test_rotation_from_angles_is_the_product_of_elementary_rotations(order, intrinsic, angles) -> None:
    factors = [elementary(name, angles["XYZ".index(name)]) for name in order.name]
    if not intrinsic:
        factors.reverse()
    expected = factors[0] @ factors[1] @ factors[2]
    m = rotation_from_angles(*angles, order=order, intrinsic=intrinsic)
    assert close(m, expected)
    assert is_rotation(m)


@pytest.mark.parametrize("order, intrinsic", COMBINATIONS, ids=COMBINATION_IDS)
@pytest.mark.parametrize("angles", ANGLE_SETS)
def test_rotation_from_angles_matches_turning_a_frame_step_by_step(order, intrinsic, angles) -> None:
    m = rotation_from_angles(*angles, order=order, intrinsic=intrinsic)
    assert close(m, moving_frame(angles, order, intrinsic))


@pytest.mark.parametrize("order", ORDERS, ids=[o.name for o in ORDERS])
def test_intrinsic_order_equals_extrinsic_reversed_order(order) -> None:
    reversed_order = RotationOrder[order.name[::-1]]
    for angles in ANGLE_SETS:
        assert close(rotation_from_angles(*angles, order=order, intrinsic=True),
                     rotation_from_angles(*angles, order=reversed_order, intrinsic=False))


def test_isg_example_60_0_90_default_order() -> None:
    # @P15=60 (A), @P16=0 (B), @P17=90 (C). First 90 about Z: X' = (0,1,0),
    # Y' = (-1,0,0), Z' = (0,0,1). Then 60 about X'' = X': Y' turns toward Z',
    # Y'' = cos60 Y' + sin60 Z' = (-1/2, 0, sqrt3/2); Z'' = cos60 Z' - sin60 Y'
    # = (sqrt3/2, 0, 1/2).
    m = rotation_from_angles(60.0, 0.0, 90.0)
    assert close(column(m, 0), (0, 1, 0))
    assert close(column(m, 1), (-0.5, 0, R3))
    assert close(column(m, 2), (R3, 0, 0.5))


def test_intrinsic_and_extrinsic_differ_for_the_same_order() -> None:
    intrinsic = rotation_from_angles(60.0, 0.0, 90.0, intrinsic=True)
    extrinsic = rotation_from_angles(60.0, 0.0, 90.0, intrinsic=False)
    # Extrinsic ZYX: 90 about the fixed Z (X -> (0,1,0)), then 60 about the fixed X
    # takes (0,1,0) to (0, 1/2, sqrt3/2).
    assert close(column(extrinsic, 0), (0, 0.5, R3))
    assert not close(intrinsic, extrinsic, tol=1e-3)


# ---------------------------------------------------------------- matrix -> angles


angle = st.floats(min_value=-179.999, max_value=180.0, allow_nan=False)
middle_angle = st.floats(min_value=-89.0, max_value=89.0, allow_nan=False)


@pytest.mark.parametrize("order, intrinsic", COMBINATIONS, ids=COMBINATION_IDS)
@given(outer1=angle, middle=middle_angle, outer2=angle)
def test_angles_round_trip_away_from_gimbal_lock(order, intrinsic, outer1, middle, outer2) -> None:
    # the middle letter of the order is the axis whose angle must stay inside +-90
    angles = [0.0, 0.0, 0.0]
    first, second, third = ("XYZ".index(name) for name in order.name)
    angles[first], angles[second], angles[third] = outer1, middle, outer2
    m = rotation_from_angles(*angles, order=order, intrinsic=intrinsic)
    assert is_rotation(m)
    result = angles_from_rotation(m, order=order, intrinsic=intrinsic)
    for got, wanted in zip(result, angles):
        assert angle_difference(got, wanted) <= 1e-9
        assert -180.0 < got <= 180.0


@pytest.mark.parametrize("order, intrinsic", COMBINATIONS, ids=COMBINATION_IDS)
@pytest.mark.parametrize("middle", [90.0, -90.0])
def test_gimbal_lock_gives_a_valid_solution_with_the_rightmost_angle_zero(
        order, intrinsic, middle) -> None:
    angles = [0.0, 0.0, 0.0]
    first, second, third = ("XYZ".index(name) for name in order.name)
    angles[first], angles[second], angles[third] = 25.0, middle, -40.0
    m = rotation_from_angles(*angles, order=order, intrinsic=intrinsic)
    result = angles_from_rotation(m, order=order, intrinsic=intrinsic)
    assert close(rotation_from_angles(*result, order=order, intrinsic=intrinsic), m, 1e-9)
    assert result[second] == pytest.approx(middle)
    # rightmost factor: the last applied intrinsic rotation, the first applied extrinsic
    rightmost = third if intrinsic else first
    assert result[rightmost] == 0.0


@pytest.mark.parametrize("order, intrinsic", COMBINATIONS, ids=COMBINATION_IDS)
def test_identity_gives_plain_zero_angles(order, intrinsic) -> None:
    result = angles_from_rotation(IDENTITY, order=order, intrinsic=intrinsic)
    assert result == (0.0, 0.0, 0.0)
    assert all(math.copysign(1.0, x) == 1.0 for x in result)  # no -0.0


def test_half_turn_is_reported_as_plus_180() -> None:
    assert angles_from_rotation(rotation_from_angles(-180.0, 0.0, 0.0)) == (180.0, 0.0, 0.0)
    assert angles_from_rotation(rotation_from_angles(0.0, 0.0, 180.0)) == (0.0, 0.0, 180.0)


def test_isg_example_angles_are_recovered() -> None:
    assert close(angles_from_rotation(rotation_from_angles(60.0, 0.0, 90.0)), (60, 0, 90))


# ---------------------------------------------------------------- matrix helpers


def test_multiply_and_transpose_by_hand() -> None:
    m = ((1.0, 2.0, 3.0), (4.0, 5.0, 6.0), (7.0, 8.0, 9.0))
    n = ((0.0, 1.0, 0.0), (0.0, 0.0, 1.0), (1.0, 0.0, 0.0))
    assert multiply(m, n) == ((3.0, 1.0, 2.0), (6.0, 4.0, 5.0), (9.0, 7.0, 8.0))
    assert multiply(n, m) == ((4.0, 5.0, 6.0), (7.0, 8.0, 9.0), (1.0, 2.0, 3.0))
    assert transpose(m) == ((1.0, 4.0, 7.0), (2.0, 5.0, 8.0), (3.0, 6.0, 9.0))
    assert multiply(IDENTITY, m) == m == multiply(m, IDENTITY)


def test_apply_maps_the_unit_vectors_onto_the_columns() -> None:
    m = rotation_from_angles(10.0, 20.0, 30.0)
    for index, unit in enumerate(((1, 0, 0), (0, 1, 0), (0, 0, 1))):
        assert close(apply(m, unit), column(m, index))
        assert close(apply_transposed(m, column(m, index)), unit)


coordinate = st.floats(min_value=-1e4, max_value=1e4, allow_nan=False)
vectors = st.tuples(coordinate, coordinate, coordinate)


@given(angles=st.tuples(angle, angle, angle), v=vectors)
def test_apply_and_apply_transposed_invert_each_other(angles, v) -> None:
    m = rotation_from_angles(*angles)
    assert close(apply_transposed(m, apply(m, v)), v, 1e-9)
    assert close(apply(m, apply_transposed(m, v)), v, 1e-9)
    assert close(apply_transposed(m, v), apply(transpose(m), v), 1e-9)


def test_is_rotation_rejects_what_is_not_a_proper_rotation() -> None:
    assert is_rotation(IDENTITY)
    assert not is_rotation(((-1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)))  # mirror
    assert not is_rotation(((2.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)))  # scaling
    assert not is_rotation(((1.0, 0.1, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)))  # shear
    assert not is_rotation(((math.nan, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)))
    nearly = ((1.0, 1e-7, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))  # shear of 1e-7
    assert not is_rotation(nearly)
    assert is_rotation(nearly, tol=1e-6)


# ---------------------------------------------------------------- reference points


def test_isg_example_points() -> None:
    # X = P2 - P1 = (0,40,0) -> (0,1,0). P3 - P1 = (15,40,-25); the normal
    # (0,40,0) x (15,40,-25) = (-1000, 0, -600) points down, so Z = (5,0,3)/sqrt34.
    # Y = Z x X = (-3,0,5)/sqrt34.
    p1, p2, p3 = (100.0, 30.0, -25.0), (100.0, 70.0, -25.0), (115.0, 70.0, -50.0)
    m = rotation_from_points(p1, p2, p3)
    r34 = math.sqrt(34.0)
    assert close(column(m, 0), (0, 1, 0))
    assert close(column(m, 1), (-3 / r34, 0, 5 / r34))
    assert close(column(m, 2), (5 / r34, 0, 3 / r34))
    assert is_rotation(m)
    # all three points lie in one plane of the new frame
    heights = [apply_transposed(m, p)[2] for p in (p1, p2, p3)]
    assert heights == pytest.approx([heights[0]] * 3, abs=1e-9)


def test_horizontal_plane_keeps_z_and_turns_x_toward_point_2() -> None:
    m = rotation_from_points((1.0, 1.0, 5.0), (3.0, 3.0, 5.0), (0.0, 4.0, 5.0))
    h = math.sqrt(0.5)
    assert close(column(m, 0), (h, h, 0))
    assert close(column(m, 1), (-h, h, 0))
    assert close(column(m, 2), (0, 0, 1))


def test_points_whose_raw_normal_points_down_still_give_z_up() -> None:
    # clockwise seen from above: (P2 - P1) x (P3 - P1) = (0,0,-1)
    m = rotation_from_points((0.0, 0.0, 0.0), (0.0, 1.0, 0.0), (1.0, 0.0, 0.0))
    assert close(column(m, 0), (0, 1, 0))
    assert close(column(m, 2), (0, 0, 1))
    assert close(column(m, 1), (-1, 0, 0))  # Z x X
    assert is_rotation(m)


def test_swapping_the_side_of_point_3_keeps_the_normal_up() -> None:
    p1, p2 = (100.0, 30.0, -25.0), (100.0, 70.0, -25.0)
    m = rotation_from_points(p1, p2, (115.0, 70.0, -50.0))
    mirrored = rotation_from_points(p1, p2, (85.0, 70.0, 0.0))  # same plane, other side
    assert close(m, mirrored)


def test_tilted_plane_about_x() -> None:
    # plane through the X axis rising 30 degrees toward +Y
    p3 = (0.0, math.cos(math.radians(30.0)), math.sin(math.radians(30.0)))
    m = rotation_from_points((0.0, 0.0, 0.0), (2.0, 0.0, 0.0), p3)
    assert close(m, rotation_from_angles(30.0, 0.0, 0.0))


def test_vertical_plane_takes_the_normal_with_positive_y() -> None:
    # plane y = 2; raw normal (1,0,0) x (0,0,1) = (0,-1,0) is flipped to +Y
    m = rotation_from_points((0.0, 2.0, 0.0), (1.0, 2.0, 0.0), (0.0, 2.0, 1.0))
    assert close(column(m, 0), (1, 0, 0))
    assert close(column(m, 2), (0, 1, 0))
    assert close(column(m, 1), (0, 0, -1))
    assert is_rotation(m)


def test_vertical_plane_normal_to_x_takes_the_normal_with_positive_x() -> None:
    # plane x = 3; raw normal (0,0,1) x (0,1,0) = (-1,0,0) is flipped to +X
    m = rotation_from_points((3.0, 0.0, 0.0), (3.0, 0.0, 1.0), (3.0, 1.0, 0.0))
    assert close(column(m, 0), (0, 0, 1))
    assert close(column(m, 2), (1, 0, 0))
    assert close(column(m, 1), (0, -1, 0))


def test_oblique_vertical_plane_takes_the_normal_with_positive_y() -> None:
    # plane x + y = 1, normal +-(1,1,0)/sqrt2
    m = rotation_from_points((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (1.0, 0.0, 7.0))
    h = math.sqrt(0.5)
    assert close(column(m, 2), (h, h, 0))


def test_small_and_large_triangles_work_alike() -> None:
    base = ((0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 1.0, 1.0))
    expected = rotation_from_points(*base)
    for scale, offset in ((1e-6, 0.0), (1e5, 1e5)):
        points = [tuple(offset + scale * c for c in p) for p in base]
        assert close(rotation_from_points(*points), expected, 1e-9)


@given(p1=vectors, p2=vectors, p3=vectors)
def test_points_give_a_rotation_with_x_along_p1_p2_and_z_up(p1, p2, p3) -> None:
    # keep to well-shaped triangles: near-degenerate ones are legal but their normal is
    # only as accurate as eps / flatness, which would make the height check flaky
    edges = [np.subtract(q, p) for p, q in ((p1, p2), (p1, p3), (p2, p3))]
    longest = max(np.linalg.norm(e) for e in edges)
    # and of a size a machine knows: a triangle of 1e-161 mm passed as "well shaped" when
    # longest**2 only had to be > 0, and one of 3e-162 mm still did (its cross product
    # is subnormal, so its normal is noise); 1e-6 mm is far below any probing accuracy
    assume(longest >= 1e-6
           and np.linalg.norm(np.cross(edges[0], edges[1])) >= 1e-3 * longest**2)
    m = rotation_from_points(p1, p2, p3)
    assert is_rotation(m)
    x = np.subtract(p2, p1)
    assert close(column(m, 0), x / np.linalg.norm(x), 1e-9)
    zx, zy, zz = column(m, 2)
    # Z up; for a vertical plane (|Z_z| <= 1e-12) the documented fallback: Y, then X up
    assert zz > 1e-12 or (abs(zz) <= 1e-12 and (zy > 1e-12 or (abs(zy) <= 1e-12 and zx > 0)))
    heights = [apply_transposed(m, p)[2] for p in (p1, p2, p3)]
    assert heights == pytest.approx([heights[0]] * 3, abs=1e-6)


COINCIDE = "reference points 1 and 2 coincide: the X axis of the plane is undefined"
COLLINEAR = "the three reference points are collinear: they define no plane"


@pytest.mark.parametrize("points", [
    ((1.0, 2.0, 3.0), (1.0, 2.0, 3.0), (5.0, 0.0, 0.0)),
    ((1.0, 2.0, 3.0), (1.0, 2.0, 3.0 + 1e-12), (5.0, 0.0, 0.0)),
    ((1.0, 2.0, 3.0), (1.0, 2.0, 3.0), (1.0, 2.0, 3.0)),
])
def test_coinciding_points_1_and_2_are_rejected(points) -> None:
    with pytest.raises(RotationError) as caught:
        rotation_from_points(*points)
    assert caught.value.message == COINCIDE
    assert str(caught.value) == COINCIDE


@pytest.mark.parametrize("points", [
    ((0.0, 0.0, 0.0), (1.0, 1.0, 1.0), (3.0, 3.0, 3.0)),
    ((0.0, 0.0, 0.0), (1.0, 1.0, 1.0), (-2.0, -2.0, -2.0)),
    ((0.0, 0.0, 0.0), (10.0, 0.0, 0.0), (5.0, 1e-10, 0.0)),
    ((0.0, 0.0, 0.0), (10.0, 0.0, 0.0), (0.0, 0.0, 0.0)),
    ((1e3, 1e3, 1e3), (2e3, 2e3, 2e3), (1e3 + 1e-9, 1e3, 1e3)),
])
def test_collinear_points_are_rejected(points) -> None:
    with pytest.raises(RotationError) as caught:
        rotation_from_points(*points)
    assert caught.value.message == COLLINEAR


def test_nearly_but_not_collinear_points_are_accepted() -> None:
    m = rotation_from_points((0.0, 0.0, 0.0), (10.0, 0.0, 0.0), (5.0, 1e-6, 0.0))
    assert close(m, IDENTITY)
