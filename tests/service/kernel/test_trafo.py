"""``#TRAFO ON`` on the five-axis machines: the program gives the tool tip and the
rotary axes, the kinematics turns them into axis positions every cycle (RTCP)."""

from __future__ import annotations

import copy
import math
from collections.abc import Iterator

import numpy as np
import pytest

from cnc_objects.service.config import build_config
from cnc_objects.service.kernel.channel_mode import ChannelState
from cnc_objects.service.machine_config import FIVE_AXIS_AC, EmbeddedMachine
from tests.service.kernel.nc.test_cs_and_patterns import EXAMPLE_1, EXAMPLE_2, PROCESSING
from tests.support.kernel import KernelHarness, Run
from tests.support.service import ROOT

X, Y, Z, A, C = 0, 1, 2, 3, 4


@pytest.fixture
def ac() -> Iterator[KernelHarness]:
    with KernelHarness(config=build_config(machine=EmbeddedMachine.FIVE_AXIS_AC)) as harness:
        yield harness


def _ran(run: Run) -> Run:
    assert run.channel.state == ChannelState.READY, run.channel.errors.entries
    return run


def tip_of(axes: tuple[float, ...], tool_mm: float = 0.0) -> np.ndarray:
    """Independent: the workpiece turned back by the table's C (about Z through the
    table's centre) and A (about X, 100 mm below the table's face)."""
    x, y, z, a, c = axes[:5]
    nose = np.array([x, y, z - tool_mm])

    def about(axis: str, deg: float, p: np.ndarray, centre: tuple[float, float, float]
              ) -> np.ndarray:
        t = math.radians(deg)
        cs, sn = math.cos(t), math.sin(t)
        m = {"x": np.array([[1, 0, 0], [0, cs, -sn], [0, sn, cs]]),
             "z": np.array([[cs, -sn, 0], [sn, cs, 0], [0, 0, 1]])}[axis]
        q = np.array(centre)
        return np.asarray(m @ (p - q) + q, dtype=np.float64)
    return about("z", -c, about("x", -a, nose, (0, 0, -100)), (0, 0, 0))


def test_the_tip_follows_the_programmed_line_while_the_table_turns(ac: KernelHarness) -> None:
    run = _ran(ac.run("G90 G01 X0 Y0 Z50 A0 C0 F3000\n#TRAFO ON\n"
                      "G01 X20 Y0 Z50 C90 F600\n#TRAFO OFF\nM30\n", record=True))
    # the last position: the tip at the workpiece's (20, 0, 50) with the table at C 90
    assert run.positions_mm[:5] == pytest.approx((0.0, 20.0, 50.0, 0.0, 90.0), abs=1e-9)
    turning = [s for s in run.samples if 0.0 < s.positions_mm[C] < 90.0]
    assert len(turning) > 100
    for sample in turning:
        tip = tip_of(sample.positions_mm)
        # on the line from (0, 0, 50) to (20, 0, 50), as far along it as C has turned
        assert tip == pytest.approx((20.0 * sample.positions_mm[C] / 90.0, 0.0, 50.0),
                                    abs=1e-9)
    # the feed acts along the tip's path: 20 mm at 10 mm/s, plus reaching and leaving
    # that speed at C's 1800 degrees/s^2, C turning 4.5 degrees per mm of path
    assert len(turning) * 0.001 == pytest.approx(20.0 / 10.0 + 10.0 / (1800.0 / 4.5),
                                                 abs=0.002)


@pytest.fixture
def ac_with_tool() -> Iterator[KernelHarness]:
    data = copy.deepcopy(FIVE_AXIS_AC)
    data["tools"] = [{"d": 7, "radius_mm": 5.0, "length_mm": 100.0}]
    with KernelHarness(config=build_config(data, machine=EmbeddedMachine.THREE_AXIS)) as h:
        yield h


def test_the_tool_length_acts_along_the_tilted_tool(ac_with_tool: KernelHarness) -> None:
    # the tip stays at the workpiece's (10, 0, 0) while the cradle tilts 30 degrees
    run = _ran(ac_with_tool.run("G90 D7 G01 X10 Y0 Z0 A0 C0 F3000\n#TRAFO ON\n"
                                "G01 A30 F600\n#TRAFO OFF\nM30\n", record=True))
    tilting = [s for s in run.samples if 0.0 < s.positions_mm[A] < 30.0]
    assert len(tilting) > 100
    for sample in tilting:
        assert tip_of(sample.positions_mm, 100.0) == pytest.approx((10.0, 0.0, 0.0),
                                                                   abs=1e-9)
    # at A 30 the tool points along the workpiece's (0, sin 30, cos 30): the nose is
    # 100 mm up that line from the tip; hand: the machine point of the workpiece's
    # (10, 0, 0) turned by A about the line (y 0, z -100): (10, -100 sin 30,
    # -100 + 100 cos 30), and the nose 100 above it
    s30, c30 = math.sin(math.radians(30)), math.cos(math.radians(30))
    x, y, z = run.positions_mm[:3]
    assert (x, y, z) == pytest.approx((10.0, -100.0 * s30, -100.0 + 100.0 * c30 + 100.0),
                                      abs=1e-9)


def test_an_axis_the_kinematics_would_drive_beyond_its_limit_stops_the_program(
        ac: KernelHarness) -> None:
    # the tip 999 mm above the table's face: tilting the cradle to A 90 (its line 100 mm
    # below the face) takes the tip to Y -(999 + 100): beyond -1000 (once referenced,
    # the software limits are monitored, P-AXIS-00705)
    ac.home()
    run = ac.run("G90 G01 X0 Y0 Z0 A0 C0 F60000\n#TRAFO ON\nG01 Z999 F60000\n"
                 "A90 F60000\nM30\n")
    assert run.channel.state == ChannelState.ERROR
    [error] = run.channel.errors.entries
    assert (error.id, error.line) == (50100, 4)
    assert "axis Y would reach" in error.text
    assert run.positions_mm[A] == pytest.approx(0.0)  # refused before it moved


def test_a_manual_block_after_trafo_on_goes_on_in_the_tip_coordinates(
        ac: KernelHarness) -> None:
    _ran(ac.mdi("G90 G01 X0 Y0 Z50 A0 C90 F3000"))
    _ran(ac.mdi("#TRAFO ON"))
    run = _ran(ac.mdi("G01 X10 F600"))
    # the tip at the workpiece's (10, 0, 50), the table at C 90: machine (0, 10, 50)
    assert run.positions_mm[:5] == pytest.approx((0.0, 10.0, 50.0, 0.0, 90.0), abs=1e-9)
    run = _ran(ac.mdi("#TRAFO OFF\nG91 G01 X5 F600"))
    assert run.positions_mm[:3] == pytest.approx((5.0, 10.0, 50.0), abs=1e-9)


def test_the_head_swivels_about_the_tip_on_the_bc_machine() -> None:
    config = build_config(machine=EmbeddedMachine.FIVE_AXIS_BC)
    chain = config.channels[0].kinematic_chain()
    assert chain is not None
    with KernelHarness(config=config) as bc:
        run = _ran(bc.run("G90 G01 X0 Y0 Z20 B0 C0 F3000\n#TRAFO ON\n"
                          "G01 B45 C30 F600\n#TRAFO OFF\nM30\n", record=True))
    swivelling = [s for s in run.samples if 0.0 < s.positions_mm[3] < 45.0]
    assert len(swivelling) > 50
    for sample in swivelling:
        values = dict(enumerate(sample.positions_mm))
        assert chain.forward(values).tip_mm == pytest.approx((0.0, 0.0, 20.0), abs=1e-9)
    # by hand at B 45 (C turns the table about the tip's line: X and Y stay): the head
    # turns the nose (0, 0, 0) about the pivot (0, 0, 150) to (-150 sin 45, 0,
    # 150 - 150 cos 45); X and Z shift it onto the tip (0, 20); cos 45 = sin 45
    s45 = math.sin(math.radians(45))
    x, _y, z = run.positions_mm[:3]
    assert (x, z) == pytest.approx((150.0 * s45, 20.0 - 150.0 + 150.0 * s45), abs=1e-9)


def tool_direction_of(axes: tuple[float, ...]) -> np.ndarray:
    """Independent: the tool (machine +Z) seen from the workpiece turned by C and A."""
    a, c = math.radians(axes[A]), math.radians(axes[C])
    rx = np.array([[1, 0, 0], [0, math.cos(-a), -math.sin(-a)], [0, math.sin(-a), math.cos(-a)]])
    rz = np.array([[math.cos(-c), -math.sin(-c), 0], [math.sin(-c), math.cos(-c), 0], [0, 0, 1]])
    return np.asarray(rz @ rx @ np.array([0.0, 0.0, 1.0]), dtype=np.float64)


def _as_printed_then(example: str, after: str) -> str:
    """The seed example up to its processing comment, then ``after`` (no #CS OFF)."""
    return example[:example.index(PROCESSING) + len(PROCESSING)] + "\n" + after


@pytest.mark.parametrize(("example", "normal"), [
    # example 1: the plane through (100, 30, -25), (100, 70, -25), (115, 70, -50): its
    # normal with a positive Z is (25, 0, 15) / |(25, 0, 15)|
    (EXAMPLE_1, np.array([25.0, 0.0, 15.0]) / math.hypot(25.0, 15.0)),
    # example 2: Rz(90) Ry(0) Rx(60) applied to Z: (sin 60, 0, cos 60)
    (EXAMPLE_2, np.array([math.sin(math.radians(60)), 0.0, math.cos(math.radians(60))])),
], ids=["points", "angles"])
def test_the_seed_examples_turn_the_tool_onto_the_plane(
        ac: KernelHarness, example: str, normal: np.ndarray) -> None:
    text = ("G90 G00 X140 Y0 Z20 A0 C0\n"
            + _as_printed_then(example, "G01 F1000 X0 Y0 Z0\nM30\n"))
    run = _ran(ac.run(text, record=True))
    final = run.positions_mm
    # the tool stands perpendicular on the plane, its tip at the plane's origin
    assert tool_direction_of(final) == pytest.approx(normal, abs=1e-9)
    assert tip_of(final) == pytest.approx((140.0, 0.0, -80.0), abs=1e-9)
    # before it turned, the tool retracted 50 mm along itself (vertical): from Z 20 to
    # 70; while the rotary axes turned, the tip stayed there (RTCP)
    turning = [s for s in run.samples if 0.0 < abs(s.positions_mm[A]) < abs(final[A])]
    assert len(turning) > 10
    for sample in turning:
        assert tip_of(sample.positions_mm) == pytest.approx((140.0, 0.0, 70.0), abs=1e-9)


def test_turning_the_tool_needs_trafo_on(ac: KernelHarness) -> None:
    text = "G90 G00 X140 Y0 Z20\n" + EXAMPLE_2.replace("#TRAFO ON", "")
    run = ac.run(text)
    [error] = run.channel.errors.entries
    assert error.id == 20519 and "program #TRAFO ON before the call" in error.text


def test_no_axis_exceeds_its_velocity_when_the_table_turns_far_from_the_tip(
        ac: KernelHarness) -> None:
    # the tip 500 mm from the table's centre: turning C at its 180 degrees/s would drive
    # X and Y at up to 500 * pi = 1571 mm/s; their limit is 500 mm/s, so the block's
    # feed is capped at 500 / (500 * pi / 180) = 57.3 degrees/s
    run = _ran(ac.run("G90 G01 X500 Y0 Z0 A0 C0 F60000\n#TRAFO ON\nG01 C90 F60000\n"
                      "#TRAFO OFF\nM30\n", record=True))
    turning = [s for s in run.samples if 0.0 < s.positions_mm[C] < 90.0]
    speeds = [math.dist(a.positions_mm[:2], b.positions_mm[:2]) / 0.001
              for a, b in zip(turning, turning[1:])]
    assert max(speeds) == pytest.approx(500.0, rel=0.002)
    assert len(turning) * 0.001 == pytest.approx(90.0 / (500.0 / (500.0 * math.pi / 180.0)),
                                                 rel=0.02)


DRILL = (ROOT / "docs" / "examples" / "cycles" / "drill.ecy").read_text()


def test_a_call_pattern_tilts_the_tool_at_a_tilted_position(ac: KernelHarness) -> None:
    # #AT about X by 30 degrees (a five-axis channel under #TRAFO ON): the tool turns
    # onto the tilted Z, the cycle drills 2 mm along it and draws its 10 mm X line;
    # the tool turns back to vertical after the pattern
    ac.programs["drill.ecy"] = DRILL
    text = ("G90 G00 X0 Y0 Z60 A0 C0\n#TRAFO ON\n#PATTERN BEGIN [ID=1]\n"
            "#AT [50, 0, 0, 30, 0, 0]\n#PATTERN END\n"
            "L CYCLE [NAME=drill.ecy @P1 = 2 PATTERN_ID = 1 PATTERN_RETRACT = 100]\nM30\n")
    run = _ran(ac.run(text, record=True))
    tilted = [s for s in run.samples if abs(s.positions_mm[A] + 30.0) < 1e-9]
    assert tilted  # the cradle at -30: the tool along the workpiece's (0, -0.5, 0.866)
    s30, c30 = math.sin(math.radians(30)), math.cos(math.radians(30))
    # the tips in the tilted system: Rx(30) about the position (50, 0, 0)
    turned = np.array([[1.0, 0.0, 0.0], [0.0, c30, -s30], [0.0, s30, c30]])
    local = [turned.T @ (tip_of(s.positions_mm) - np.array([50.0, 0.0, 0.0])) for s in tilted]
    on_axis = [p for p in local if abs(p[0]) < 1e-9 and abs(p[1]) < 1e-9]
    assert min(p[2] for p in on_axis) == pytest.approx(-2.0, abs=0.02)  # drilled 2 mm
    on_x_line = [p for p in local if abs(p[1]) < 1e-9 and abs(p[2] + 2.0) < 1e-9
                 and 0.0 < p[0] < 10.0]
    assert len(on_x_line) > 100  # the cycle's X line, at 1000 mm/min: 0.6 s
    assert tool_direction_of(tilted[0].positions_mm) == pytest.approx((0.0, -s30, c30),
                                                                       abs=1e-9)
    assert run.positions_mm[A] == pytest.approx(0.0)  # turned back at the end


def test_a_tilted_position_needs_trafo_on(ac: KernelHarness) -> None:
    ac.programs["drill.ecy"] = DRILL
    run = ac.run("#PATTERN BEGIN [ID=1]\n#AT [50, 0, 0, 30, 0, 0]\n#PATTERN END\n"
                 "L CYCLE [NAME=drill.ecy @P1 = 2 PATTERN_ID = 1 PATTERN_RETRACT = 100]\nM30\n")
    [error] = run.channel.errors.entries
    assert error.id == 20526 and "program #TRAFO ON before the call" in error.text


def test_a_tilt_beyond_the_cradle_is_refused_before_anything_moves(ac: KernelHarness) -> None:
    # 130 degrees about X: the cradle would need A -130 or +130, beyond its 120
    text = ("G90 G00 X0 Y0 Z50 A0 C0\n#TRAFO ON\n"
            "L CYCLE [NAME=SysPosRotationToPlane.ecy @P1=2 @P15=130]\nM30\n")
    run = ac.run(text)
    [error] = run.channel.errors.entries
    assert (error.id, error.line) == (292004, 3)
    assert "beyond their limits" in error.text
    assert run.positions_mm[A] == 0.0


def test_of_two_solutions_the_one_inside_the_limits_is_taken() -> None:
    # 100 degrees about X from A 0 C 0: the nearer solution is A -100, C 0; with the
    # cradle's range -30..120 only A 100 with C 180 is inside
    data = copy.deepcopy(FIVE_AXIS_AC)
    data["channels"][0]["axes"][3]["limits"]["sw_limit_min_mm"] = -30.0
    config = build_config(data, machine=EmbeddedMachine.THREE_AXIS)
    with KernelHarness(config=config) as ac:
        run = _ran(ac.run("G90 G00 X0 Y0 Z50 A0 C0\n#TRAFO ON\n"
                          "L CYCLE [NAME=SysPosRotationToPlane.ecy @P1=2 @P15=100]\nM30\n"))
    assert (run.positions_mm[A], run.positions_mm[C]) == pytest.approx((100.0, 180.0))


def test_a_simultaneous_part_a_half_circle_while_the_table_turns(ac: KernelHarness) -> None:
    """Simultaneous five-axis: the tip runs a half circle of R10 about the workpiece's
    origin (G02 under #TRAFO ON) while C turns 90 degrees with it, tracking."""
    run = _ran(ac.run("G90 G01 X10 Y0 Z0 A0 C0 F3000\n#TRAFO ON\n"
                      "G02 X-10 Y0 I-10 J0 C90 F600\n#TRAFO OFF\nM30\n", record=True))
    moving = [s for s in run.samples if 0.0 < s.positions_mm[C] < 90.0]
    assert len(moving) > 1000
    for sample in moving:
        x, y, z = tip_of(sample.positions_mm)
        assert math.hypot(x, y) == pytest.approx(10.0, abs=1e-9) and z == pytest.approx(0.0)
        swept = math.degrees(math.atan2(-y, x)) % 360.0  # clockwise from (10, 0)
        assert sample.positions_mm[C] == pytest.approx(swept / 2.0, abs=1e-6)
    assert run.positions_mm[:5] == pytest.approx((0.0, -10.0, 0.0, 0.0, 90.0), abs=1e-9)


def test_a_three_plus_two_part_a_square_in_a_tilted_plane(ac: KernelHarness) -> None:
    """3+2: the tool tilted onto a plane turned 30 degrees about X (origin (20, 0, 0)),
    then a 20 mm square milled 1 mm deep in it; every corner checked against numpy."""
    corners = [(0.0, 0.0), (20.0, 0.0), (20.0, 20.0), (0.0, 20.0), (0.0, 0.0)]
    square = "\n".join(f"G01 X{x:g} Y{y:g} Z-1 F3000" for x, y in corners)
    run = _ran(ac.run("G90 G00 X20 Y0 Z30 A0 C0\n#TRAFO ON\n"
                      "L CYCLE [NAME=SysPosRotationToPlane.ecy @P1=1 @P2=10 @P3=20 @P4=0 "
                      f"@P5=0 @P15=30]\n{square}\nM30\n", record=True))
    s30, c30 = math.sin(math.radians(30)), math.cos(math.radians(30))
    turned = np.array([[1.0, 0.0, 0.0], [0.0, c30, -s30], [0.0, s30, c30]])
    expected = [np.array([20.0, 0.0, 0.0]) + turned @ np.array([x, y, -1.0])
                for x, y in corners]
    tips = [tip_of(s.positions_mm) for s in run.samples]
    for corner in expected:
        assert min(float(np.linalg.norm(t - corner)) for t in tips) < 0.06  # 3000 mm/min
    final = run.positions_mm
    assert tip_of(final) == pytest.approx(tuple(expected[-1]), abs=1e-9)
    assert tool_direction_of(final) == pytest.approx((0.0, -s30, c30), abs=1e-9)


# ------------------------------------- point-vector programming: #ORI MODE [VECTOR_2DOF]


@pytest.mark.parametrize("vector", [(0.0, -0.5, 0.8660254), (-0.5, 0.5, 0.7071),
                                    (0.3, 0.0, 1.0), (0.0, 0.0, 2.0)])
def test_a_b_c_are_the_tool_direction_in_vector_mode(
        ac: KernelHarness, vector: tuple[float, float, float]) -> None:
    """ISG's point-vector form (``X50 Y50 Z100 A-0.5 B0.5 C0.7071`` of the programming
    manual, and others): the tool points along (A, B, C), not normalised, its tip at
    X Y Z; checked with the independent numpy model of the machine."""
    a, b, c = vector
    run = _ran(ac.run("G90 G01 X0 Y0 Z100 A0 C0 F3000\n#ORI MODE [VECTOR_2DOF]\n#TRAFO ON\n"
                      f"G01 X50 Y50 Z100 A{a} B{b} C{c} F3000\nG01 X40\n#TRAFO OFF\nM30\n"))
    final = run.positions_mm
    unit = np.array(vector) / np.linalg.norm(vector)
    assert tool_direction_of(final) == pytest.approx(tuple(unit), abs=1e-7)
    assert tip_of(final) == pytest.approx((40.0, 50.0, 100.0), abs=1e-7)
    assert -120.0 <= final[A] <= 120.0


def test_the_nearer_of_the_two_solutions_and_angle_mode_again(ac: KernelHarness) -> None:
    """(0, 0.5, 0.866) is A 30 C 0 or A -30 C 180: from A -10 C 170 the second is
    nearer; ``#ORI MODE [ANGLE]`` makes A an angle again."""
    run = _ran(ac.run("G90 G01 X0 Y0 Z50 A-10 C170 F3000\n#ORI MODE [VECTOR_2DOF]\n"
                      "#TRAFO ON\nG01 A0 B0.5 C0.8660254\n#TRAFO OFF\nM30\n"))
    assert (run.positions_mm[A], run.positions_mm[C]) == pytest.approx((-30.0, 180.0))
    run = _ran(ac.run("#ORI MODE [VECTOR_2DOF]\n#ORI MODE [ANGLE]\n#TRAFO ON\n"
                      "G01 A-20 F3000\n#TRAFO OFF\nM30\n", "angle.nc"))
    assert (run.positions_mm[A], run.positions_mm[C]) == pytest.approx((-20.0, 180.0))


@pytest.mark.parametrize(("text", "error_id", "column"), [
    # outside VECTOR_2DOF, or without #TRAFO ON, B is no axis of the A/C machine
    ("#TRAFO ON\nG01 X0 A0 B1 C1 F100", 21220, 11),
    ("#ORI MODE [VECTOR_2DOF]\nG01 X0 A0 B1 C1 F100", 21220, 11),
    ("#ORI MODE [VECTOR_2DOF]\n#TRAFO ON\nG01 X0 A0 B0 C0 F100", 20113, 8),
    # 130 degrees from the vertical: the cradle turns to 120 at most
    ("#ORI MODE [VECTOR_2DOF]\n#TRAFO ON\nG01 A0 B-0.766 C-0.6428 F100", 292004, 5),
    ("#ORI MODE [VECTOR_ABC]", 20500, 12),
    ("#ORI MODE [POLAR]", 20530, 12),
])
def test_bad_orientation_vectors(ac: KernelHarness, text: str, error_id: int, column: int
                                 ) -> None:
    run = ac.run("G90 G00 X0 Y0 Z50 A0 C0\n" + text + "\nM30\n")
    [error] = run.channel.errors.entries
    assert (error.id, error.line, error.column) == (error_id, text.count("\n") + 2, column)
    assert run.positions_mm[A] == 0.0
