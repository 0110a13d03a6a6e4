"""Machining coordinate systems (#CS), SysPosRotationToPlane, call patterns (#PATTERN,
SysPosPattern) and #MSG, through the decoder (CYCLES-ADC §3)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from cnc_objects.service.config import build_config
from cnc_objects.service.kernel.nc import MotionKind, NcError, NcErrorId, StopKind
from cnc_objects.service.kernel.path.kinematics import Kinematics
from cnc_objects.service.machine_config import EmbeddedMachine

from .cycle_support import Channel, assert_at

E = NcErrorId


def rot(axis: str, deg: float) -> np.ndarray:
    """Right-hand rotation about a coordinate axis (written independently of the kernel)."""
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
    if axis == "X":
        return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])
    if axis == "Y":
        return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def cs_matrix(a: float, b: float, c: float) -> np.ndarray:
    """#CS ON [.., a, b, c]: first c about Z, then b about the new Y, then a about the
    newest X (each about the rotated axes)."""
    return rot("Z", c) @ rot("Y", b) @ rot("X", a)


# ---------------------------------------------------------------- 8. #CS

def test_cs_rotated_90_degrees_about_z() -> None:
    text = ("G01 F100\n#CS ON [10, 20, 30, 0, 0, 90]\nX1 Y2 Z3\nX5\nG91 X1 Y1\nG90\n"
            "#CS OFF\nX7 Y8 Z9\nM30\n")
    d, moves = Channel().moves(text)
    assert [m.motion.end_mm for m in moves] == [
        (8.0, 21.0, 33.0),  # (10, 20, 30) + Rz90 (1, 2, 3), exact
        (8.0, 25.0, 33.0),  # only X: the CS Y and Z stay 2 and 3
        (7.0, 26.0, 33.0),  # G91 in the CS: +1 along CS X (machine +Y), +1 along CS Y (-X)
        (7.0, 8.0, 9.0),  # #CS OFF: machine coordinates
    ]
    assert [m.motion.kind for m in moves] == [MotionKind.LINEAR] * 4
    assert d.modal.cs_placement is None and d.modal.cs == ()


def test_cs_with_general_angles() -> None:
    text = "G01 F100\n#CS ON [1, 2, 3, 10, 20, 30]\nX4 Y5 Z6\nG91 Z2\nM30\n"
    _, moves = Channel().moves(text)
    r = cs_matrix(10, 20, 30)
    first = np.array([1, 2, 3]) + r @ np.array([4, 5, 6])
    second = np.array([1, 2, 3]) + r @ np.array([4, 5, 8])
    assert moves[0].motion.end_mm == pytest.approx(tuple(first), abs=1e-9)
    assert moves[1].motion.end_mm == pytest.approx(tuple(second), abs=1e-9)


def test_cs_offset_only() -> None:
    _, moves = Channel().moves("G01 F100\n#CS ON [5, -5, 1]\nX1 Y1 Z1\nM30\n")
    assert moves[0].motion.end_mm == (6.0, -4.0, 2.0)


def test_word_for_one_axis_keeps_the_others_in_a_rotated_cs() -> None:
    # the machine starts at (3, 4, 5); in the CS the point has some Y and Z that stay
    text = "G00 X3 Y4 Z5\n#CS ON [0, 0, 0, 0, 0, 30]\nG01 F100 X10\nM30\n"
    _, moves = Channel().moves(text)
    r = cs_matrix(0, 0, 30)
    start_cs = r.T @ np.array([3, 4, 5])
    end = r @ np.array([10, start_cs[1], start_cs[2]])
    assert moves[1].motion.end_mm == pytest.approx(tuple(end), abs=1e-9)
    assert moves[1].motion.end_mm[2] == 5.0


def test_a_cs_without_a_move_leaves_the_machine_position() -> None:
    d, moves = Channel().moves("G00 X3 Y4 Z5\n#CS ON [1, 1, 1, 0, 0, 37]\nG01 F100\n#CS OFF\n"
                               "X3\nM30\n")
    assert [m.motion.end_mm for m in moves] == [(3.0, 4.0, 5.0)]  # X3 is where it is


def test_nested_cs_is_relative_to_the_first() -> None:
    text = ("G01 F100\n#CS ON [10, 0, 0, 0, 0, 90]\n#CS ON [5, 0, 0, 0, 0, 90]\nX1 Y0 Z0\n"
            "#CS OFF\nX1 Y0 Z0\n#CS ON [0, 0, 2]\n#CS ON [1, 1, 1]\n#CS OFF ALL\nX1 Y0 Z0\nM30\n")
    _, moves = Channel().moves(text)
    assert [m.motion.end_mm for m in moves] == [
        (9.0, 5.0, 0.0),  # origin (10,0,0) + Rz90 (5,0,0) = (10,5,0), rotated 180: X1 -> -1
        (10.0, 1.0, 0.0),  # the second one deselected: the first is active again
        (1.0, 0.0, 0.0),  # #CS OFF ALL
    ]


def test_nested_cs_with_general_angles() -> None:
    text = ("G01 F100\n#CS ON [10, -3, 4, 15, 0, 40]\n#CS ON [2, 5, -1, 0, 25, -70]\n"
            "X3 Y-2 Z7\nM30\n")
    _, moves = Channel().moves(text)
    r1, r2 = cs_matrix(15, 0, 40), cs_matrix(0, 25, -70)
    expected = np.array([10, -3, 4]) + r1 @ (np.array([2, 5, -1]) + r2 @ np.array([3, -2, 7]))
    assert moves[0].motion.end_mm == pytest.approx(tuple(expected), abs=1e-9)


def test_cs_def_then_on_by_name() -> None:
    text = ("G01 F100\n#CS DEF [Tilt] [1, 2, 3, 0, 0, 30]\nX1 Y0 Z0\n#CS ON [Tilt]\n"
            "X1 Y0 Z0\n#CS OFF\n#CS ON [Tilt]\nX0 Y0 Z0\nM30\n")
    d, moves = Channel().moves(text)
    assert moves[0].motion.end_mm == (1.0, 0.0, 0.0)  # DEF alone selects nothing
    assert moves[1].motion.end_mm == pytest.approx(
        (1 + math.cos(math.radians(30)), 2 + math.sin(math.radians(30)), 3.0), abs=1e-12)
    assert moves[2].motion.end_mm == pytest.approx((1.0, 2.0, 3.0), abs=1e-12)
    assert len(d.modal.cs) == 1


def test_cs_on_with_an_undefined_name() -> None:
    text = "#CS ON [Nope]\nM30\n"
    error = Channel().error(text)
    assert_at(error, E.INSTRUCTION_SYNTAX, text, "#CS")
    assert "NOPE" in error.message.upper()


@pytest.mark.parametrize("line", ["#CS ON [1, 2]", "#CS ON [1, 2, 3, 4]", "#CS DEF [1, 2, 3]",
                                  "#CS ON", "#CS FOO [1, 2, 3]", "#CS ON [1, 2, 3] X1"])
def test_malformed_cs(line) -> None:
    error = Channel().error(f"{line}\nM30\n")
    assert error.id == E.INSTRUCTION_SYNTAX and error.line == 1


def test_arc_in_a_cs_rotated_about_z() -> None:
    text = "G01 F100\n#CS ON [10, 20, 0, 0, 0, 90]\nX0 Y0\nG02 X10 Y0 I5 J0\nG03 X0 Y0 R5\nM30\n"
    _, moves = Channel().moves(text)
    cw, ccw = moves[1].motion, moves[2].motion
    assert (cw.kind, cw.start_mm, cw.end_mm, cw.center_mm, cw.plane) == \
        (MotionKind.ARC_CW, (10.0, 20.0, 0.0), (10.0, 30.0, 0.0), (10.0, 25.0), (0, 1))
    assert (ccw.kind, ccw.end_mm, ccw.center_mm) == \
        (MotionKind.ARC_CCW, (10.0, 20.0, 0.0), (10.0, 25.0))


def test_arc_in_a_cs_rotated_by_an_odd_angle_about_z() -> None:
    text = "G01 F100\n#CS ON [3, 4, 5, 0, 0, 33]\nX2 Y1 Z0\nG03 X-1 Y4 I-3 J0\nM30\n"
    _, moves = Channel().moves(text)
    r = cs_matrix(0, 0, 33)
    o = np.array([3, 4, 5])
    arc = moves[1].motion
    assert arc.kind == MotionKind.ARC_CCW and arc.plane == (0, 1)
    assert arc.end_mm == pytest.approx(tuple(o + r @ np.array([-1, 4, 0])), abs=1e-9)
    assert arc.center_mm == pytest.approx(tuple((o + r @ np.array([-1, 1, 0]))[:2]), abs=1e-9)


def test_cs_turned_over_about_x_flips_the_arc_direction() -> None:
    text = "G01 F100\n#CS ON [0, 0, 0, 180, 0, 0]\nX0 Y1\nG02 X10 Y1 I5 J0\nM30\n"
    _, moves = Channel().moves(text)
    arc = moves[-1].motion
    assert arc.kind == MotionKind.ARC_CCW  # clockwise seen from the CS +Z = machine -Z
    assert arc.start_mm == (0.0, -1.0, 0.0) and arc.end_mm == (10.0, -1.0, 0.0)
    assert arc.center_mm == (5.0, -1.0) and arc.plane == (0, 1)


def test_g18_arc_in_a_cs_rotated_about_z_runs_in_the_machine_yz_plane() -> None:
    # the CS ZX plane is the machine YZ plane, its normal CS +Y is machine -X
    text = "G01 F100\n#CS ON [0, 0, 0, 0, 0, 90]\nG18 G02 X10 Z0 I5 K0\nM30\n"
    _, moves = Channel().moves(text)
    arc = moves[0].motion
    assert arc.plane == (1, 2)
    assert arc.end_mm == (0.0, 10.0, 0.0) and arc.center_mm == (5.0, 0.0)
    assert arc.kind == MotionKind.ARC_CCW


def test_arc_in_a_tilted_cs() -> None:
    text = "G01 F100\n#CS ON [0, 0, 0, 30, 0, 0]\nX0 Y0\nG02 X10 Y0 I5 J0\nM30\n"
    error = Channel().error(text)
    assert int(E.ARC_PLANE_TILTED) == 20148
    assert_at(error, E.ARC_PLANE_TILTED, text, "G02")
    # a straight line in the same CS is fine
    _, moves = Channel().moves(text.replace("G02 X10 Y0 I5 J0", "X10 Y0"))
    assert moves[-1].motion.end_mm == pytest.approx((10.0, 0.0, 0.0), abs=1e-12)


def test_program_start_resets_the_cs() -> None:
    channel = Channel()
    first, _ = channel.run("G01 F100\n#CS DEF [A] [0, 0, 0, 0, 0, 45]\n#CS ON [100, 0, 0, 0, 0, 90]\n"
                           "X1\nM30\n")
    assert first.modal.cs_placement is not None
    modal = first.modal
    # manual blocks (MDI) continue in the CS
    manual, blocks = channel.run("X1 Y0 Z0", modal=modal, manual=True)
    assert blocks[-1].motion.end_mm == (100.0, 1.0, 0.0)
    # a program start does not
    d, blocks = channel.run("G01 F100 X1 Y2 Z3\nM30\n", modal=modal)
    assert blocks[0].motion.end_mm == (1.0, 2.0, 3.0)
    assert d.modal.cs == () and d.modal.cs_placement is None
    error = channel.error("#CS ON [A]\nM30\n", modal=d.modal)  # #CS DEF is gone too
    assert error.id == E.INSTRUCTION_SYNTAX


# ---------------------------------------------------------------- 9. SysPosRotationToPlane

EXAMPLE_1 = """#TRAFO ON
L CYCLE [NAME=SysPosRotationToPlane.ecy \\  

    @P1 = 1 \\


@P2 = 50          \\
@P3 = 140        \\
@P4 = 0          \\
@P5 = -80        \\
@P6 = 100        \\
@P7 = 30         \\
@P8 = -25        \\
@P9 = 100        \\
@P10 = 70        \\
@P11 = -25       \\
@P12 = 115       \\
@P13 = 70        \\
@P14 = -50       \\
]

(-----)
(---- Processing the plane ----)
(-----)

#CS OFF ; Deactivate the calculated MCS

#TRAFO OFF
"""

EXAMPLE_2 = """#TRAFO ON

L CYCLE [NAME=SysPosRotationToPlane.ecy \\
@P1 = 1          \\  
@P2 = 50        \\  
@P3 = 140       \\  
@P4 = 0         \\  
@P5 = -80       \\  
@P15 = 60       \\  
@P16 = 0        \\  
@P17 = 90       \\  
]  
(-----)  
(---- Processing the plane ----)  
(-----)  
  
#CS OFF ; Deactivate the calculated MCS  
  
#TRAFO OFF  
  
M30
"""

PROCESSING = "(---- Processing the plane ----)"


def processing(example: str, lines: str) -> str:
    """The example with @P1=3 (only the MCS is rotated) and NC lines where the plane is
    processed."""
    return example.replace("@P1 = 1", "@P1 = 3").replace(PROCESSING, PROCESSING + "\n" + lines)


def test_example_1_as_documented_needs_a_kinematic_transformation() -> None:
    text = "G00 X1 Y2 Z3\n" + EXAMPLE_1 + "M30\n"
    error = Channel().error(text)
    assert int(E.TRAFO_NOT_CONFIGURED) == 20519
    assert_at(error, E.TRAFO_NOT_CONFIGURED, text, "@P1")
    assert "kinematic transformation" in error.message


def test_example_2_as_documented_needs_a_kinematic_transformation() -> None:
    error = Channel().error(EXAMPLE_2)
    assert_at(error, E.TRAFO_NOT_CONFIGURED, EXAMPLE_2, "@P1")


def test_example_1_rotates_the_mcs_onto_the_plane_of_the_points() -> None:
    text = "G00 X1 Y2 Z3\n" + processing(EXAMPLE_1, "G01 F100 X0 Y0 Z0\nX10\nY10\nZ10\nM0") \
        + "G01 X1 Y2 Z3\nM30\n"
    d = Channel().decoder(text)
    blocks = []
    for block in d.blocks():
        blocks.append(block)
        if block.stop == StopKind.PROGRAMMED:  # M0: the CS is active here
            placement = d.modal.cs_placement
            break
    else:
        raise AssertionError("no M0")
    x = np.array([0.0, 1.0, 0.0])
    z = np.array([5.0, 0.0, 3.0]) / math.sqrt(34.0)
    y = np.cross(z, x)
    r = np.array(placement.rotation)
    assert r[:, 0] == pytest.approx(x, abs=1e-12)
    assert r[:, 1] == pytest.approx(y, abs=1e-12)
    assert r[:, 2] == pytest.approx(z, abs=1e-12)
    assert placement.origin_mm == pytest.approx((140.0, 0.0, -80.0), abs=1e-12)
    moves = [b for b in blocks if b.motion is not None]
    retract = moves[1]
    assert retract.source.file == "SysPosRotationToPlane.ecy"
    assert retract.motion.kind == MotionKind.RAPID
    assert retract.motion.start_mm == (1.0, 2.0, 3.0)
    assert retract.motion.end_mm == pytest.approx((1.0, 2.0, 53.0), abs=1e-12)  # +@P2 along Z
    origin = np.array([140.0, 0.0, -80.0])
    ends = [m.motion.end_mm for m in moves[2:]]
    assert len(ends) == 4
    assert ends[0] == pytest.approx(tuple(origin), abs=1e-9)
    assert ends[1] == pytest.approx(tuple(origin + 10 * x), abs=1e-9)
    assert ends[2] == pytest.approx(tuple(origin + 10 * x + 10 * y), abs=1e-9)
    assert ends[3] == pytest.approx(tuple(origin + 10 * x + 10 * y + 10 * z), abs=1e-9)


def test_example_1_points_lie_in_a_plane_parallel_to_the_new_xy_plane() -> None:
    text = "G00 Z0\n" + processing(EXAMPLE_1, "M30")
    d, _ = Channel().run(text)
    placement = d.modal.cs_placement
    heights = [placement.from_machine(p)[2] for p in
               ((100, 30, -25), (100, 70, -25), (115, 70, -50))]
    assert heights == pytest.approx([heights[0]] * 3, abs=1e-9)
    x_new = [placement.from_machine(p)[0] for p in ((100, 30, -25), (100, 70, -25))]
    assert x_new[1] - x_new[0] == pytest.approx(40.0, abs=1e-9)  # X along point 1 -> 2


def _ac_chain() -> Kinematics:
    chain = build_config(machine=EmbeddedMachine.FIVE_AXIS_AC).channels[0].kinematic_chain()
    assert chain is not None
    return chain


def test_example_1_runs_with_a_kinematic_transformation() -> None:
    chain = _ac_chain()
    d, blocks = Channel(kinematics=chain).run("G00 X1 Y2 Z3 A0 C0\n" + EXAMPLE_1 + "M30\n")
    moves = [b for b in blocks if b.motion is not None]
    # the retraction along the (vertical) tool, then the rotary axes turn the tool onto
    # the plane's normal (25, 0, 15) / |.|, the tip staying (tip coordinates: #TRAFO ON)
    assert moves[1].motion.end_mm == pytest.approx((1.0, 2.0, 53.0, 0.0, 0.0), abs=1e-12)
    turned = moves[2].motion.end_mm
    assert turned[:3] == pytest.approx((1.0, 2.0, 53.0), abs=1e-12)
    normal = np.array([25.0, 0.0, 15.0]) / math.hypot(25.0, 15.0)
    assert chain.forward({3: turned[3], 4: turned[4]}).orientation == pytest.approx(
        tuple(normal), abs=1e-9)
    assert d.modal.cs == ()  # the example deselects the MCS with #CS OFF
    assert d.modal.settings.trafo is False


def test_example_2_by_angles() -> None:
    text = "G00 X1 Y2 Z3\n" + processing(EXAMPLE_2, "G01 F100 X10 Y0 Z0\nX0 Y10 Z0\nX0 Y0 Z10")
    text = text.replace("#TRAFO OFF", "X0 Y0 Z10\n#TRAFO OFF")
    _, moves = Channel().moves(text)
    r = rot("Z", 90) @ rot("Y", 0) @ rot("X", 60)  # ZYX intrinsic: Z first
    origin = np.array([140.0, 0.0, -80.0])
    assert moves[1].motion.end_mm == pytest.approx((1.0, 2.0, 53.0), abs=1e-12)
    for move, axis in zip(moves[2:5], np.eye(3)):
        assert move.motion.end_mm == pytest.approx(tuple(origin + 10 * r @ axis), abs=1e-9)
    # X of the new CS is machine +Y, Z is tilted 60 degrees from machine Z toward +X
    assert moves[2].motion.end_mm == pytest.approx((140.0, 10.0, -80.0), abs=1e-9)
    assert moves[4].motion.end_mm == pytest.approx(
        (140.0 + 10 * math.sin(math.radians(60)), 0.0, -80.0 + 10 * math.cos(math.radians(60))),
        abs=1e-9)
    assert moves[-1].motion.end_mm == pytest.approx((0.0, 0.0, 10.0), abs=1e-12)  # #CS OFF


ORDERS = {1: "XYZ", 2: "XZY", 3: "YXZ", 4: "YZX", 5: "ZXY", 6: "ZYX"}


@pytest.mark.parametrize("order", sorted(ORDERS))
@pytest.mark.parametrize("mode", [1, 2])
def test_rotation_orders(order, mode) -> None:
    a, b, c = 17.0, -29.0, 41.0
    text = (f"L CYCLE [NAME=SysPosRotationToPlane.ecy @P1=3 @P3=1 @P4=-2 @P5=3 @P15={a} "
            f"@P16={b} @P17={c} @P18={mode} @P19={order}]\nG01 F100 X4 Y5 Z6\nM30\n")
    d, moves = Channel().moves(text)
    angle = {"X": a, "Y": b, "Z": c}
    factors = [rot(axis, angle[axis]) for axis in ORDERS[order]]
    if mode == 1:  # intrinsic: about the rotated axes, the first rotation leftmost
        expected = factors[0] @ factors[1] @ factors[2]
    else:  # extrinsic: about the fixed axes, the first rotation rightmost
        expected = factors[2] @ factors[1] @ factors[0]
    assert np.array(d.modal.cs_placement.rotation) == pytest.approx(expected, abs=1e-9)
    end = np.array([1, -2, 3]) + expected @ np.array([4, 5, 6])
    assert moves[-1].motion.end_mm == pytest.approx(tuple(end), abs=1e-9)


def test_default_order_is_zyx_intrinsic_like_cs_on() -> None:
    a, b, c = 12.0, 34.0, -56.0
    text = (f"L CYCLE [NAME=SysPosRotationToPlane.ecy @P1=3 @P15={a} @P16={b} @P17={c}]\n"
            "M30\n")
    d, _ = Channel().run(text)
    assert np.array(d.modal.cs_placement.rotation) == pytest.approx(cs_matrix(a, b, c), abs=1e-9)


def test_rotation_refers_to_the_active_cs() -> None:
    text = ("#CS ON [10, 0, 0, 0, 0, 90]\n"
            "L CYCLE [NAME=SysPosRotationToPlane.ecy @P1=3 @P3=5 @P17=90]\n"
            "G01 F100 X1 Y0 Z0\n#CS OFF\nX1 Y0 Z0\n#CS OFF\nX1 Y0 Z0\nM30\n")
    _, moves = Channel().moves(text)
    assert moves[0].motion.end_mm == pytest.approx((9.0, 5.0, 0.0), abs=1e-12)
    assert moves[1].motion.end_mm == pytest.approx((10.0, 1.0, 0.0), abs=1e-12)
    assert moves[2].motion.end_mm == (1.0, 0.0, 0.0)


def test_retraction_is_along_machine_z_in_a_rotated_cs() -> None:
    text = ("G00 X1 Y2 Z3\n#CS ON [4, 5, 6, 20, 70, 10]\n"
            "L CYCLE [NAME=SysPosRotationToPlane.ecy @P1=3 @P2=10 @P15=5]\nM30\n")
    _, moves = Channel().moves(text)
    retract = moves[-1]
    assert retract.source.file == "SysPosRotationToPlane.ecy"
    assert retract.motion.end_mm == pytest.approx((1.0, 2.0, 13.0), abs=1e-9)


def test_callers_modal_functions_survive_the_retraction() -> None:
    text = ("G91 G01 F100 X1\nL CYCLE [NAME=SysPosRotationToPlane.ecy @P1=3 @P2=5 @P15=0]\n"
            "X1\nM30\n")
    _, moves = Channel().moves(text)
    assert moves[1].motion.kind == MotionKind.RAPID
    last = moves[-1].motion
    assert last.kind == MotionKind.LINEAR  # G01 again
    assert last.end_mm == pytest.approx((2.0, 0.0, 5.0), abs=1e-12)  # G91 again


RESULT_1 = [
    "SysPosRotationToPlane result",
    "Mode = 3",
    "Origin = 140.000000, 0.000000, -80.000000",
    "X axis = 0.000000, 1.000000, 0.000000",
    "Y axis = -0.514496, 0.000000, 0.857493",
    "Z axis = 0.857493, 0.000000, 0.514496",
]


def test_result_file_of_example_1() -> None:
    channel = Channel({"SysPosRotationToPlaneResult.txt": "old\n"})
    text = processing(EXAMPLE_1, "M30").replace("@P14 = -50       \\", "@P14 = -50 @P20 = 1 \\")
    d, _ = channel.run(text)
    lines = channel.files["SysPosRotationToPlaneResult.txt"].splitlines()
    assert lines[:6] == RESULT_1  # replaced, not appended
    assert len(lines) == 7 and lines[6].startswith("#CS ON [")
    # the last line selects the same coordinate system
    cs_line = lines[6]
    check, _ = Channel().run(cs_line + "\nM30\n")
    assert np.array(check.modal.cs_placement.rotation) == \
        pytest.approx(np.array(d.modal.cs_placement.rotation), abs=1e-5)
    assert check.modal.cs_placement.origin_mm == pytest.approx((140.0, 0.0, -80.0), abs=1e-6)


def test_mode_4_only_writes_the_result() -> None:
    channel = Channel()
    text = ("G00 X1 Y2 Z3\nL CYCLE [NAME=SysPosRotationToPlane.ecy @P1=4 @P2=50 @P3=140 @P5=-80 "
            "@P6=100 @P7=30 @P8=-25 @P9=100 @P10=70 @P11=-25 @P12=115 @P13=70 @P14=-50 "
            "@P20=1]\nG01 F100 X0 Y0 Z0\nM30\n")
    d, moves = channel.moves(text)
    assert [m.motion.end_mm for m in moves] == [(1.0, 2.0, 3.0), (0.0, 0.0, 0.0)]
    assert d.modal.cs == () and d.modal.cs_placement is None
    lines = channel.files["SysPosRotationToPlaneResult.txt"].splitlines()
    assert lines[1] == "Mode = 4"
    assert lines[2:6] == RESULT_1[2:6]


def test_no_result_file_without_p20() -> None:
    channel = Channel()
    channel.run("L CYCLE [NAME=SysPosRotationToPlane.ecy @P1=4 @P15=10]\nM30\n")
    assert channel.files == {}


def test_mode_2_with_kinematics_rotates_no_mcs() -> None:
    # @P1=2: only the tool is rotated (was: the MCS was rotated too)
    text = ("G00 X1 Y2 Z3\n#TRAFO ON\n"
            "L CYCLE [NAME=SysPosRotationToPlane.ecy @P1=2 @P2=5 @P3=10 @P15=30]\n"
            "G01 F100 X0 Y0 Z0\nM30\n")
    d, moves = Channel(kinematics=_ac_chain()).moves(text)
    assert moves[1].motion.end_mm == pytest.approx((1.0, 2.0, 8.0, 0.0, 0.0), abs=1e-12)
    # the tool tilts 30 degrees about X (towards -Y): the cradle A by -30, C stays (the
    # other solution, A 30 with C 180, is farther from A 0 C 0)
    assert moves[2].motion.end_mm[3:] == pytest.approx((-30.0, 0.0), abs=1e-9)
    assert moves[3].motion.end_mm[:3] == pytest.approx((0.0, 0.0, 0.0), abs=1e-12)
    assert d.modal.cs == ()
    assert Channel().error(text).id == E.TRAFO_NOT_CONFIGURED


POINTS = "@P6={} @P7={} @P8={} @P9={} @P10={} @P11={} @P12={} @P13={} @P14={}"


@pytest.mark.parametrize("coords, err_id", [
    ((1, 2, 3, 1, 2, 3, 5, 5, 5), E.CYCLE_POINTS_IDENTICAL),  # points 1 and 2 coincide
    ((0, 0, 0, 1, 1, 1, 3, 3, 3), E.CYCLE_POINTS_COLLINEAR),
    ((0, 0, 0, 1, 0, 0, 0, 0, 0), E.CYCLE_POINTS_COLLINEAR),  # point 3 on point 1
])
def test_degenerate_reference_points(coords, err_id) -> None:
    text = f"L CYCLE [NAME=SysPosRotationToPlane.ecy @P1=3 {POINTS.format(*coords)}]\nM30\n"
    error = Channel().error(text)
    assert_at(error, err_id, text, "@P6")


def test_points_and_angles_together() -> None:
    text = (f"L CYCLE [NAME=SysPosRotationToPlane.ecy @P1=3 {POINTS.format(0, 0, 0, 1, 0, 0, 0, 1, 0)}"
            " @P16=10]\nM30\n")
    error = Channel().error(text)
    assert_at(error, E.CYCLE_PARAMETER_UNKNOWN, text, "@P16")
    assert "@P16" in error.message


def test_partial_reference_points() -> None:
    text = "L CYCLE [NAME=SysPosRotationToPlane.ecy @P1=3 @P6=0 @P7=0 @P8=0 @P9=1 @P10=0]\nM30\n"
    error = Channel().error(text)
    assert error.id == E.CYCLE_PARAMETER_MISSING and "@P11" in error.message


def test_no_plane_at_all() -> None:
    error = Channel().error("L CYCLE [NAME=SysPosRotationToPlane.ecy @P1=3 @P2=5]\nM30\n")
    assert error.id == E.CYCLE_PARAMETER_MISSING


@pytest.mark.parametrize("param", ["@P1=5", "@P1=0", "@P2=-1", "@P18=3", "@P19=7", "@P20=2",
                                   "@P19=1.5"])
def test_rotation_parameters_out_of_range(param) -> None:
    text = f"L CYCLE [NAME=SysPosRotationToPlane.ecy @P15=10 {param}]\nM30\n"
    error = Channel().error(text)
    assert_at(error, E.CYCLE_PARAMETER_RANGE, text, param)


# ---------------------------------------------------------------- 10. call patterns

PATTERN_CYCLE = "; user cycle at a pattern position\nG01 X10 Y0 Z-2 F100\nM17\n"

PATTERN_PROGRAM = """#VAR
; parameters for pattern:
V.CYC.PatternRetract = 100
V.CYC.PatternID      = 1
#ENDVAR

; pattern data
#PATTERN BEGIN [ID=V.CYC.PatternID]
#AT [100, 0, 0]
#AT [100, 100, 5, 0, 0, 60]
#AT [0 , 100, 10]
#PATTERN END

G00 Z60
G00 X50 Y50          ( Positioning to the starting point )

L CYCLE [NAME=pocket.ecy \\
  @P1 = 0 \\
  PATTERN_ID = V.CYC.PatternID \\
  PATTERN_RETRACT = V.CYC.PatternRetract \\
]
G01 X1 Y1 Z1
X2
M30
"""


def test_cycle_runs_at_every_pattern_position() -> None:
    d, moves = Channel({"pocket.ecy": PATTERN_CYCLE}).moves(PATTERN_PROGRAM)
    positions = [((100.0, 0.0, 0.0), 0.0), ((100.0, 100.0, 5.0), 60.0),
                 ((0.0, 100.0, 10.0), 0.0)]
    expected = [("prog.nc", MotionKind.RAPID, (0.0, 0.0, 60.0)),
                ("prog.nc", MotionKind.RAPID, (50.0, 50.0, 60.0))]
    last = (50.0, 50.0)
    for (x, y, z), c in positions:
        cut = np.array([x, y, z]) + rot("Z", c) @ np.array([10.0, 0.0, -2.0])
        expected += [
            ("SysPosPatternWrapper.ecy", MotionKind.RAPID, (*last, 100.0)),  # retract
            ("SysPosPatternWrapper.ecy", MotionKind.RAPID, (x, y, 100.0)),  # approach
            ("pocket.ecy", MotionKind.LINEAR, tuple(cut)),  # the cycle in the rotated CS
        ]
        last = (float(cut[0]), float(cut[1]))
    expected.append(("SysPosPatternWrapper.ecy", MotionKind.RAPID, (*last, 100.0)))
    expected += [("prog.nc", MotionKind.LINEAR, (1.0, 1.0, 1.0)),
                 ("prog.nc", MotionKind.LINEAR, (2.0, 1.0, 1.0))]  # caller's G01, no CS
    got = [(m.source.file, m.motion.kind, m.motion.end_mm) for m in moves]
    assert [g[:2] for g in got] == [e[:2] for e in expected]
    for g, e in zip(got, expected):
        assert g[2] == pytest.approx(e[2], abs=1e-9)
    # the second position: X10 of the cycle runs 60 degrees turned, Z relative to Z5
    assert got[7][2] == pytest.approx(
        (105.0, 100.0 + 10 * math.sin(math.radians(60)), 3.0), abs=1e-9)
    assert d.modal.cs == () and d.modal.cs_placement is None


def test_pattern_call_passes_the_cycle_parameters_each_time() -> None:
    files = {"p.ecy": '#MSG SAVE ["%g", @P1]\nM17\n'}
    text = ("#PATTERN BEGIN [ID7]\n#AT [1, 2, 3]\n#AT [4, 5, 6]\n#PATTERN END\n"
            "L CYCLE [NAME=p.ecy @P1=42 PATTERN_ID=7 PATTERN_RETRACT=20]\nM30\n")
    channel = Channel(files)
    channel.run(text)
    assert channel.files["msg_save.txt"] == "42\n42\n"


def test_pattern_with_a_builtin_cycle() -> None:
    text = ("#VAR\nV.CYC.SysRetRadius\n#ENDVAR\n#PATTERN BEGIN [ID=1]\n#AT [1, 2, 3]\n#AT [4, 5, 6]\n"
            "#PATTERN END\nL CYCLE [NAME=SysCalcCircle.ecy @P50=0 @P60=-1 @P51=0 @P61=1 @P52=1 "
            "@P62=0 PATTERN_ID=1 PATTERN_RETRACT=5]\nM30\n")
    channel = Channel()
    _, moves = channel.moves(text.replace("M30", '#MSG ["%g", V.CYC.SysRetRadius]\nM30'))
    # retract, approach, (the cycle moves nothing), retract (none: Z is there), approach,
    # final retract (none)
    assert [m.motion.end_mm for m in moves] == [(0.0, 0.0, 5.0), (1.0, 2.0, 5.0),
                                                (4.0, 5.0, 5.0)]
    assert channel.messages == ["1"]


def test_pattern_redefinition_replaces_the_positions() -> None:
    text = ("#PATTERN BEGIN [ID=1]\n#AT [1, 2, 3]\n#PATTERN END\n#PATTERN BEGIN [ID=1]\n"
            "#AT [7, 8, 9]\n#PATTERN END\nL CYCLE [NAME=c.ecy PATTERN_ID=1 PATTERN_RETRACT=50]\n"
            "M30\n")
    _, moves = Channel({"c.ecy": PATTERN_CYCLE}).moves(text)
    assert [m.motion.end_mm for m in moves] == [
        (0.0, 0.0, 50.0), (7.0, 8.0, 50.0), (17.0, 8.0, 7.0), (17.0, 8.0, 50.0)]


def test_pattern_keeps_the_callers_modal_state() -> None:
    text = ("G91 G00 X1\n#PATTERN BEGIN [ID=1]\n#AT [10, 20, 3]\n#PATTERN END\n"
            "L CYCLE [NAME=c.ecy PATTERN_ID=1 PATTERN_RETRACT=5]\nX1\nM30\n")
    _, moves = Channel({"c.ecy": PATTERN_CYCLE}).moves(text)
    last = moves[-1].motion
    assert (last.kind, last.start_mm, last.end_mm) == \
        (MotionKind.RAPID, (20.0, 20.0, 5.0), (21.0, 20.0, 5.0))


def test_undefined_pattern() -> None:
    text = "L CYCLE [NAME=c.ecy PATTERN_ID=3 PATTERN_RETRACT=5]\nM30\n"
    error = Channel({"c.ecy": PATTERN_CYCLE}).error(text)
    assert_at(error, E.PATTERN_NOT_DEFINED, text, "PATTERN_ID")


def test_pattern_id_without_retract() -> None:
    text = "#PATTERN BEGIN [ID=1]\n#AT [1,2,3]\n#PATTERN END\nL CYCLE [NAME=c.ecy PATTERN_ID=1]\nM30\n"
    error = Channel({"c.ecy": PATTERN_CYCLE}).error(text)
    assert error.id == E.CYCLE_PARAMETER_MISSING and error.line == 4
    assert "PATTERN_RETRACT" in error.message


def test_retract_without_pattern_id() -> None:
    text = "L CYCLE [NAME=c.ecy PATTERN_RETRACT=5]\nM30\n"
    error = Channel({"c.ecy": PATTERN_CYCLE}).error(text)
    assert_at(error, E.CYCLE_PARAMETER_UNKNOWN, text, "PATTERN_RETRACT")


def test_nested_pattern_begin() -> None:
    text = "#PATTERN BEGIN [ID=1]\n#AT [1, 2, 3]\n#PATTERN BEGIN [ID=2]\n#PATTERN END\nM30\n"
    assert_at(Channel().error(text), E.PATTERN_NESTED, text, "#PATTERN BEGIN", 1)


@pytest.mark.parametrize("line", ["G01 F100 X1", "#CS ON [1, 2, 3]", "#MSG [\"x\"]",
                                  "V.P.NOPE = 1", "L CYCLE [NAME=c.ecy]"])
def test_commands_inside_a_definition(line) -> None:
    text = f"#PATTERN BEGIN [ID=1]\n#AT [1, 2, 3]\n{line}\n#PATTERN END\nM30\n"
    error = Channel({"c.ecy": PATTERN_CYCLE}).error(text)
    assert error.id == E.PATTERN_COMMAND_INSIDE and error.line == 3


@pytest.mark.parametrize("values, needle", [("1, 2, 3, 5, 0, 0", "5"), ("1, 2, 3, 0, -5, 0", "-5")])
def test_pattern_rotation_about_x_or_y(values, needle) -> None:
    text = f"#PATTERN BEGIN [ID=1]\n#AT [{values}]\n#PATTERN END\nM30\n"
    error = Channel().error(text)
    assert_at(error, E.PATTERN_ROTATION_NOT_SUPPORTED, text, needle)


def test_at_outside_a_definition() -> None:
    text = "G01 F100 X1\n#AT [1, 2, 3]\nM30\n"
    assert_at(Channel().error(text), E.PATTERN_SYNTAX, text, "#AT")


@pytest.mark.parametrize("line", ["#AT [1, 2]", "#AT [1, 2, 3, 4]", "#AT 1, 2, 3"])
def test_malformed_at(line) -> None:
    # (was INSTRUCTION_SYNTAX; errors.py gives malformed #AT its own id)
    text = f"#PATTERN BEGIN [ID=1]\n{line}\n#PATTERN END\nM30\n"
    error = Channel().error(text)
    assert error.id == E.PATTERN_SYNTAX and error.line == 2


@pytest.mark.parametrize("text", ["#PATTERN FOO\nM30\n", "#PATTERN BEGIN\nM30\n",
                                  "#PATTERN BEGIN [ID=1.5]\nM30\n", "#PATTERN END\nM30\n",
                                  "#PATTERN BEGIN [ID=1]\n#PATTERN END\nM30\n",
                                  "#PATTERN END X\nM30\n"])
def test_malformed_pattern(text) -> None:
    assert Channel().error(text).id == E.PATTERN_SYNTAX


def test_pattern_call_outside_the_pattern_wrapper() -> None:
    """#PATTERN CALL belongs to the wrapper a cycle call at a pattern runs."""
    text = "G01 F100 X1\n#PATTERN CALL\nM30\n"
    error = Channel().error(text)
    assert_at(error, E.PATTERN_SYNTAX, text, "#PATTERN CALL")
    assert "belongs to the pattern wrapper" in str(error)


def test_missing_pattern_end_at_program_end() -> None:
    text = "G01 F100 X1\n#PATTERN BEGIN [ID=4]\n#AT [1, 2, 3]\n"
    error = Channel().error(text)
    assert_at(error, E.PATTERN_NOT_CLOSED, text, "#PATTERN")


def test_deleted_pattern_is_not_defined() -> None:
    text = ("#PATTERN BEGIN [ID=1]\n#AT [1, 2, 3]\n#PATTERN END\n#PATTERN DELETE [ID=1]\n"
            "L CYCLE [NAME=c.ecy PATTERN_ID=1 PATTERN_RETRACT=5]\nM30\n")
    error = Channel({"c.ecy": PATTERN_CYCLE}).error(text)
    assert (error.id, error.line) == (E.PATTERN_NOT_DEFINED, 5)


def test_delete_all() -> None:
    text = ("#PATTERN BEGIN [ID=1]\n#AT [1, 2, 3]\n#PATTERN END\n#PATTERN BEGIN [ID=2]\n"
            "#AT [4, 5, 6]\n#PATTERN END\n#PATTERN DELETE ALL\n"
            "L CYCLE [NAME=c.ecy PATTERN_ID=2 PATTERN_RETRACT=5]\nM30\n")
    d = Channel({"c.ecy": PATTERN_CYCLE}).decoder(text)
    with pytest.raises(NcError) as info:
        list(d.blocks())
    assert (info.value.id, info.value.line) == (E.PATTERN_NOT_DEFINED, 8)
    assert d.modal.patterns == {}


def test_delete_spelled_as_in_the_documentation() -> None:
    text = ("#PATTERN BEGIN [ID=3]\n#AT [1, 2, 3]\n#PATTERN END\n"
            "#PATTERN BEGIN [ID=4]\n#AT [4, 5, 6]\n#PATTERN END\n"
            "# PATTERN DELETE [ID3] ( Delete specific call pattern with ID3)\n")
    channel = Channel({"c.ecy": PATTERN_CYCLE})
    d, _ = channel.run(text + "L CYCLE [NAME=c.ecy PATTERN_ID=4 PATTERN_RETRACT=5]\nM30\n")
    assert sorted(d.modal.patterns) == [4]
    error = channel.error(text + "L CYCLE [NAME=c.ecy PATTERN_ID=3 PATTERN_RETRACT=5]\nM30\n")
    assert (error.id, error.line) == (E.PATTERN_NOT_DEFINED, 8)
    d, _ = channel.run(text + "# PATTERN DELETE ALL ( Delete all call patterns)\nM30\n")
    assert d.modal.patterns == {}


def test_delete_of_an_undefined_pattern() -> None:
    text = "#PATTERN DELETE [ID=4]\nM30\n"
    assert_at(Channel().error(text), E.PATTERN_NOT_DEFINED, text, "4")


def test_patterns_end_with_the_program() -> None:
    channel = Channel({"c.ecy": PATTERN_CYCLE})
    first, _ = channel.run("#PATTERN BEGIN [ID=1]\n#AT [1, 2, 3]\n#PATTERN END\nM30\n")
    assert list(first.modal.patterns) == [1]
    error = channel.error("L CYCLE [NAME=c.ecy PATTERN_ID=1 PATTERN_RETRACT=5]\nM30\n",
                          modal=first.modal)
    assert error.id == E.PATTERN_NOT_DEFINED


# ---------------------------------------------------------------- 11. #MSG

def test_msg_goes_to_the_message_list() -> None:
    channel = Channel()
    channel.run('#MSG ["text %d", 3]\n#VAR\nV.L.A = 2.5\n#ENDVAR\n'
                '#MSG ["%5.2f|%-4d|%s|%%|%x|%e", V.L.A * 2, 7.9, "abc", 255, 12345.678]\nM30\n')
    assert channel.messages == ["text 3", " 5.00|7   |abc|%|ff|1.234568e+04"]
    assert channel.files == {}


@pytest.mark.parametrize("line", ['#MSG ["text %d"]', '#MSG ["text", 3]', '#MSG ["%d", "a"]',
                                  '#MSG ["%q", 1]', '#MSG ["%200f", 1]',
                                  '#MSG SAVE ["%d %d", 1]'])
def test_msg_format_errors(line) -> None:
    channel = Channel()
    text = f"G01 F100 X1\n{line}\nM30\n"
    error = channel.error(text)
    assert_at(error, E.MESSAGE_FORMAT, text, '"')
    assert channel.messages == [] and channel.files == {}
