"""The five-axis chain (ISG Universal Kinematics) against an independent model.

The independent model is the physical one, built with numpy: the table's rotary axes
turn the workpiece about their lines (C rides on A's cradle), the head's rotary axis
turns the tool about its pivot, the linear axes shift the tool. The tool tip in
workpiece coordinates is then the machine point taken back through the table's turns.
The chain under test instead follows ISG's description (axes from the workpiece to the
tool, workpiece-side directions times -1); both must give the same tip and direction.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from cnc_objects.service.kernel.path.kinematics import (
    ChainAxis,
    JointKind,
    Kinematics,
    KinematicsError,
)

T, R = JointKind.TRANSLATOR, JointKind.ROTATOR
X, Y, Z, A, B, C = 0, 1, 2, 3, 4, 5
# a table-table machine: C table on an A cradle, X Y Z move the tool
A_LINE_POINT = (0.0, 20.0, -150.0)  # the cradle's axis, parallel to X
C_LINE_POINT = (5.0, -3.0, 0.0)  # the table's axis, parallel to Z
AC_SPINDLE_NOSE = (0.0, 0.0, 400.0)
TABLE_AC = Kinematics.from_chain(
    1, (0, 0, 1), AC_SPINDLE_NOSE,
    [ChainAxis(C, R, (0, 0, -1), C_LINE_POINT), ChainAxis(A, R, (-1, 0, 0), A_LINE_POINT),
     ChainAxis(X, T, (1, 0, 0)), ChainAxis(Y, T, (0, 1, 0)), ChainAxis(Z, T, (0, 0, 1))])
# a head-table machine: C table, X Y Z, a B head pivoting about Y
B_PIVOT = (0.0, 0.0, 550.0)
BC_SPINDLE_NOSE = (0.0, 0.0, 300.0)
HEAD_TABLE_BC = Kinematics.from_chain(
    2, (0, 0, 1), BC_SPINDLE_NOSE,
    [ChainAxis(C, R, (0, 0, -1), C_LINE_POINT), ChainAxis(X, T, (1, 0, 0)),
     ChainAxis(Y, T, (0, 1, 0)), ChainAxis(Z, T, (0, 0, 1)), ChainAxis(B, R, (0, 1, 0), B_PIVOT)])

angles = st.floats(-360.0, 360.0, allow_nan=False)
lengths = st.floats(-500.0, 500.0, allow_nan=False)
tools = st.floats(0.0, 200.0, allow_nan=False)


def turn_np(axis: tuple[float, float, float], deg: float) -> np.ndarray:
    """Rotation matrix about a unit axis (scipy-free, via the matrix exponential form)."""
    u = np.array(axis, dtype=float) / np.linalg.norm(axis)
    k = np.array([[0, -u[2], u[1]], [u[2], 0, -u[0]], [-u[1], u[0], 0]])
    t = math.radians(deg)
    return np.asarray(np.eye(3) + math.sin(t) * k + (1 - math.cos(t)) * k @ k, dtype=np.float64)


def about_line(axis: tuple[float, float, float], point: tuple[float, float, float],
               deg: float, p: np.ndarray) -> np.ndarray:
    q = np.array(point)
    return np.asarray(turn_np(axis, deg) @ (p - q) + q, dtype=np.float64)


def table_ac_model(x: float, y: float, z: float, a: float, c: float,
                   tool_mm: float) -> tuple[np.ndarray, np.ndarray]:
    """Physical model: the workpiece turns by c about C's line, which turns by a with
    the cradle; the tip in workpiece coordinates undoes both turns."""
    tip_machine = np.array(AC_SPINDLE_NOSE) + [x, y, z] - tool_mm * np.array([0, 0, 1.0])
    # workpiece -> machine: first C (on the cradle), then A: m = TA(a) TC(c) w
    w = about_line((0, 0, 1), C_LINE_POINT, -c,
                   about_line((1, 0, 0), A_LINE_POINT, -a, tip_machine))
    direction = turn_np((0, 0, 1), -c) @ turn_np((1, 0, 0), -a) @ np.array([0, 0, 1.0])
    return w, direction


def head_table_bc_model(x: float, y: float, z: float, b: float, c: float,
                        tool_mm: float) -> tuple[np.ndarray, np.ndarray]:
    nose = np.array(BC_SPINDLE_NOSE) - tool_mm * np.array([0, 0, 1.0])
    tip_machine = about_line((0, 1, 0), B_PIVOT, b, nose) + [x, y, z]
    w = about_line((0, 0, 1), C_LINE_POINT, -c, tip_machine)
    direction = turn_np((0, 0, 1), -c) @ turn_np((0, 1, 0), b) @ np.array([0, 0, 1.0])
    return w, direction


@pytest.mark.parametrize(("kinematics", "first_rotator", "model"), [
    (TABLE_AC, A, table_ac_model), (HEAD_TABLE_BC, B, head_table_bc_model),
], ids=["AC", "BC"])
@given(x=lengths, y=lengths, z=lengths, r=angles, c=angles, tool_mm=tools)
def test_tip_and_direction_match_the_physical_model(
        kinematics: Kinematics, first_rotator: int, model: Any, x: float, y: float,
        z: float, r: float, c: float, tool_mm: float) -> None:
    pose = kinematics.forward({X: x, Y: y, Z: z, first_rotator: r, C: c}, tool_mm)
    tip, direction = model(x, y, z, r, c, tool_mm)
    assert np.allclose(pose.tip_mm, tip, atol=1e-9)
    assert np.allclose(pose.orientation, direction, atol=1e-12)


def test_a_quarter_turn_of_the_cradle_by_hand() -> None:
    # A = 90: the cradle turns the workpiece's +Y up to +Z; seen from the workpiece the
    # tool (pointing +Z in the machine) points along workpiece -Y... worked out: the tool
    # tip at machine (0, 0, 400) relative to the A line (y 20, z -150) is (0, -20, 550);
    # turned by -90 about X: (0, 550, 20), back on the line: (0, 570, -130); C = 0.
    pose = TABLE_AC.forward({A: 90.0})
    assert pose.tip_mm == pytest.approx((0.0, 570.0, -130.0))
    assert pose.orientation == pytest.approx((0.0, 1.0, 0.0))


@pytest.mark.parametrize("kinematics", [TABLE_AC, HEAD_TABLE_BC], ids=["AC", "BC"])
@given(tip=st.tuples(lengths, lengths, lengths), r1=angles, r2=angles, tool_mm=tools)
def test_rtcp_puts_the_tip_where_it_was_programmed(
        kinematics: Kinematics, tip: tuple[float, float, float], r1: float, r2: float,
        tool_mm: float) -> None:
    first, second = kinematics.rotators
    values = kinematics.tip_to_axes(tip, {first.axis_index: r1, second.axis_index: r2},
                                    tool_mm)
    assert kinematics.forward(values, tool_mm).tip_mm == pytest.approx(tip, abs=1e-9)
    assert values[first.axis_index] == r1 and values[second.axis_index] == r2


def test_rtcp_moves_the_linear_axes_when_only_the_table_turns() -> None:
    # the tip stays at the workpiece's (10, 0, 0) while C turns 90: the line of C is at
    # (5, -3), the point (5, 3) from it; the table turns that to (-3, 5): machine
    # (2, 2, 0); the spindle nose is 400 above the tip
    values = TABLE_AC.tip_to_axes((10.0, 0.0, 0.0), {A: 0.0, C: 90.0})
    assert (values[X], values[Y], values[Z]) == pytest.approx((2.0, 2.0, -400.0))


@pytest.mark.parametrize("kinematics", [TABLE_AC, HEAD_TABLE_BC], ids=["AC", "BC"])
@given(r1=angles, r2=angles)
def test_the_rotary_values_for_a_direction_turn_the_tool_there(
        kinematics: Kinematics, r1: float, r2: float) -> None:
    first, second = kinematics.rotators
    wanted = kinematics.forward({first.axis_index: r1, second.axis_index: r2}).orientation
    found = kinematics.orientation_to_rotary(wanted, {first.axis_index: r1,
                                                      second.axis_index: r2})
    # 1e-7: near the singular pose the solution is good to ~1e-8 rad (1 - cos cancels),
    # 0.01 um at a 100 mm tool, far below the axes' resolution of 0.0001 degrees
    assert kinematics.forward(found).orientation == pytest.approx(wanted, abs=1e-7)
    if abs(wanted[2]) < 1 - 1e-6:  # away from the singular pose both are determined
        assert found[first.axis_index] == pytest.approx(r1, abs=1e-6)
        assert found[second.axis_index] == pytest.approx(r2, abs=1e-6)


def test_of_two_solutions_the_one_nearer_the_current_position_is_taken() -> None:
    tilted = TABLE_AC.forward({A: 30.0, C: 40.0}).orientation
    assert TABLE_AC.orientation_to_rotary(tilted, {A: 25.0, C: 35.0}) == pytest.approx(
        {A: 30.0, C: 40.0})
    # the other solution: A -30 with C turned half a turn
    other = TABLE_AC.orientation_to_rotary(tilted, {A: -25.0, C: 215.0})
    assert other == pytest.approx({A: -30.0, C: 220.0})


def test_a_tool_along_the_c_axis_keeps_c_where_it_is() -> None:
    assert TABLE_AC.orientation_to_rotary((0.0, 0.0, 1.0), {A: 0.1, C: 123.0}) == (
        pytest.approx({A: 0.0, C: 123.0}))


def test_a_direction_out_of_a_nutating_heads_reach_is_refused() -> None:
    s = math.sqrt(0.5)
    nutating = Kinematics.from_chain(
        3, (0, 0, 1), (0, 0, 0),
        [ChainAxis(X, T, (1, 0, 0)), ChainAxis(Y, T, (0, 1, 0)), ChainAxis(Z, T, (0, 0, 1)),
         ChainAxis(C, R, (0, 0, 1)), ChainAxis(B, R, (0, s, s))])
    assert nutating.forward(nutating.orientation_to_rotary((1.0, 0.0, 0.0), {})).orientation \
        == pytest.approx((1.0, 0.0, 0.0), abs=1e-12)
    with pytest.raises(KinematicsError, match="out of the rotators' reach"):
        nutating.orientation_to_rotary((0.0, 0.0, -1.0), {})


@pytest.mark.parametrize(("chain", "message"), [
    ([ChainAxis(X, T, (1, 0, 0)), ChainAxis(Y, T, (0, 1, 0)), ChainAxis(Z, T, (0, 0, 1)),
      ChainAxis(A, T, (1, 0, 0)), ChainAxis(C, R, (0, 0, 1))], "has 3 translators and 2"),
    ([ChainAxis(X, T, (1, 0, 0)), ChainAxis(Y, T, (1, 0, 0)), ChainAxis(Z, T, (0, 0, 1)),
      ChainAxis(A, R, (1, 0, 0)), ChainAxis(C, R, (0, 0, 1))], "do not span space"),
    ([ChainAxis(X, T, (1, 0, 0)), ChainAxis(Y, T, (0, 1, 0)), ChainAxis(Z, T, (0, 0, 1)),
      ChainAxis(X, R, (1, 0, 0)), ChainAxis(C, R, (0, 0, 1))], "an axis is in the chain twice"),
    ([ChainAxis(X, T, (1, 0, 0)), ChainAxis(Y, T, (0, 1, 0)), ChainAxis(Z, T, (0, 0, 0)),
      ChainAxis(A, R, (1, 0, 0)), ChainAxis(C, R, (0, 0, 1))], "is not a vector"),
])
def test_a_chain_that_is_no_five_axis_machine_is_refused(chain: list[ChainAxis],
                                                         message: str) -> None:
    with pytest.raises(KinematicsError, match=message):
        Kinematics.from_chain(9, (0, 0, 1), (0, 0, 0), chain)
