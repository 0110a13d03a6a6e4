"""Motion blocks: G0/G1/G2/G3, I/J/K and R arcs, G90/G91, planes, F, D, compensation."""

from __future__ import annotations

import math

import pytest

from cnc_objects.service.kernel.nc import Compensation, MotionKind, NcErrorId

from .support import decode, error_of, motions, slow

INF = math.inf


@pytest.mark.parametrize(
    ("program", "expected"),
    [
        # program text -> [(kind, start, end, feed_mm_s)]
        ("G0 X10 Y5\nM30", [(MotionKind.RAPID, (0, 0, 0), (10, 5, 0), INF)]),
        ("G1 X10 F600\nY5\nM30", [(MotionKind.LINEAR, (0, 0, 0), (10, 0, 0), 10.0),
                                  (MotionKind.LINEAR, (10, 0, 0), (10, 5, 0), 10.0)]),
        ("G01 X1 F60\nG00 Z2\nX3\nM30", [(MotionKind.LINEAR, (0, 0, 0), (1, 0, 0), 1.0),
                                          (MotionKind.RAPID, (1, 0, 0), (1, 0, 2), INF),
                                          (MotionKind.RAPID, (1, 0, 2), (3, 0, 2), INF)]),
        ("G91 G1 X10 F120\nX10 Y-5\nG90 X0\nM30",
         [(MotionKind.LINEAR, (0, 0, 0), (10, 0, 0), 2.0),
          (MotionKind.LINEAR, (10, 0, 0), (20, -5, 0), 2.0),
          (MotionKind.LINEAR, (20, -5, 0), (0, -5, 0), 2.0)]),
        ("G1X1.5Y-.5F100\nM30", [(MotionKind.LINEAR, (0, 0, 0), (1.5, -0.5, 0), 100 / 60)]),
        ("G1 X+2. F100\nM30", [(MotionKind.LINEAR, (0, 0, 0), (2, 0, 0), 100 / 60)]),
        ("F100\nX1\nM30", [(MotionKind.LINEAR, (0, 0, 0), (1, 0, 0), 100 / 60)]),  # G1 default
    ],
)
def test_linear_and_rapid(program, expected) -> None:
    for text in (program, slow(program)):
        got = [(m.kind, m.start_mm, m.end_mm, m.feed_mm_s) for m in motions(text)]
        assert got == [(k, tuple(map(float, s)), tuple(map(float, e)), f)
                       for k, s, e, f in expected]


@pytest.mark.parametrize(
    ("program", "kind", "centre", "end"),
    [
        # quarter circle by I/J (offsets from the start point)
        ("G1 X10 F100\nG3 X0 Y10 I-10 J0\nM30", MotionKind.ARC_CCW, (0, 0), (0, 10, 0)),
        ("G1 X10 F100\nG2 X0 Y-10 I-10\nM30", MotionKind.ARC_CW, (0, 0), (0, -10, 0)),
        # R > 0: arc up to 180 degrees; R < 0: the longer arc (centre on the other side)
        ("G1 X10 F100\nG3 X0 Y10 R10\nM30", MotionKind.ARC_CCW, (0, 0), (0, 10, 0)),
        ("G1 X10 F100\nG3 X0 Y10 R-10\nM30", MotionKind.ARC_CCW, (10, 10), (0, 10, 0)),
        ("G1 X10 F100\nG2 X0 Y10 R10\nM30", MotionKind.ARC_CW, (10, 10), (0, 10, 0)),
        ("G1 X10 F100\nG2 X0 Y10 R-10\nM30", MotionKind.ARC_CW, (0, 0), (0, 10, 0)),
        # half circle: R gives the centre on the chord
        ("G1 F100\nG2 X10 R5\nM30", MotionKind.ARC_CW, (5, 0), (10, 0, 0)),
        # full circle: end == start, centre from I/J
        ("G1 X10 F100\nG2 I5 J0\nM30", MotionKind.ARC_CW, (15, 0), (10, 0, 0)),
        ("G1 X10 F100\nG3 X10 Y0 I-2\nM30", MotionKind.ARC_CCW, (8, 0), (10, 0, 0)),
        # incremental end point; I/J stay relative to the start
        ("G91 G1 X10 F100\nG3 X-10 Y10 I-10\nM30", MotionKind.ARC_CCW, (0, 0), (0, 10, 0)),
        # within the 1e-3 mm tolerance
        ("G1 X10 F100\nG3 X0 Y10.0009 I-10\nM30", MotionKind.ARC_CCW, (0, 0), (0, 10.0009, 0)),
    ],
)
def test_arcs_in_g17(program, kind, centre, end) -> None:
    for text in (program, slow(program)):
        arc = motions(text)[-1]
        assert arc.kind == kind
        assert arc.plane == (0, 1)
        assert arc.center_mm == pytest.approx(centre, abs=1e-9)
        assert arc.end_mm == pytest.approx(end)
        assert arc.feed_mm_s == pytest.approx(100 / 60)


@pytest.mark.parametrize(
    ("program", "plane", "centre"),
    [
        ("G17 G1 X10 F100\nG2 X0 Y10 I-10\nM30", (0, 1), (0, 0)),  # X,Y with I,J
        ("G18 G1 X10 F100\nG2 X0 Z10 I-10\nM30", (2, 0), (0, 0)),  # Z,X with K,I: (z, x)
        ("G18 G1 Z10 F100\nG2 Z0 X10 K-10\nM30", (2, 0), (0, 0)),
        ("G19 G1 Y10 F100\nG3 Y0 Z10 J-10\nM30", (1, 2), (0, 0)),  # Y,Z with J,K
        ("G19 G1 Y10 F100\nG3 Y0 Z10 J-10 K0\nM30", (1, 2), (0, 0)),
    ],
)
def test_planes(program, plane, centre) -> None:
    for text in (program, slow(program)):
        arc = motions(text)[-1]
        assert arc.plane == plane
        assert arc.center_mm == pytest.approx(centre)


def test_plane_indices_follow_the_channel_axis_order() -> None:
    arc = motions("G1 X10 F100\nG2 X0 Y-10 I-10\nM30", axes=("Y", "X", "Z"))[-1]
    assert arc.plane == (1, 0)  # X is channel axis 1, Y axis 0
    assert arc.end_mm == (-10, 0, 0)
    assert arc.center_mm == (0, 0)


@pytest.mark.parametrize(
    ("program", "err", "line", "column"),
    [
        ("G1 X10\nM30", NcErrorId.NO_FEED, 1, 1),
        ("G0 X1\nG2 X2 I1\nM30", NcErrorId.NO_FEED, 2, 1),
        ("G1 X10 F0\nM30", NcErrorId.INVALID_FEED, 1, 8),
        ("G1 X10 F-5\nM30", NcErrorId.INVALID_FEED, 1, 8),
        ("G1 F100\nG2 X20 I6\nM30", NcErrorId.ARC_RADIUS_DIFFERENCE, 2, 1),
        ("G1 F100\n  X5 G2 Y5 R1\nM30", NcErrorId.ARC_RADIUS_TOO_SMALL, 2, 3),
        ("G1 F100\nG2 R5\nM30", NcErrorId.ARC_FULL_CIRCLE_WITH_R, 2, 1),
        ("G1 F100\nG2 X10 R0\nM30", NcErrorId.ARC_RADIUS_ZERO, 2, 1),
        ("G1 F100\nG2 X10 I0 J0\nM30", NcErrorId.ARC_RADIUS_ZERO, 2, 1),
        ("G1 F100\nG2 X10\nM30", NcErrorId.MISSING_VALUE, 2, 1),
        ("G1 F100\nG2 X10 I5 R5\nM30", NcErrorId.ARC_CENTRE_AND_RADIUS, 2, 11),
        ("G1 F100\nG2 X10 K5\nM30", NcErrorId.ARC_OFFSET_OUT_OF_PLANE, 2, 8),
        ("G1 F100 X1 I5\nM30", NcErrorId.ARC_WORDS_WITHOUT_ARC, 1, 12),
        ("G0 X1 R5\nM30", NcErrorId.ARC_WORDS_WITHOUT_ARC, 1, 7),
        ("G1 X1 X2 F100\nM30", NcErrorId.WORD_REPEATED, 1, 7),
        ("G0 G1 X1\nM30", NcErrorId.CONFLICTING_G_CODES, 1, 4),
        ("G1 F100 D7 X1\nM30", NcErrorId.TOOL_NOT_IN_TABLE, 1, 9),
        ("G1 F100 D1.5 X1\nM30", NcErrorId.TOOL_NOT_IN_TABLE, 1, 9),
        ("G1 X1.2.3 F100\nM30", NcErrorId.UNKNOWN_WORD, 1, 8),
        ("G1 X F100\nM30", NcErrorId.MISSING_VALUE, 1, 4),
        ("G1 X" + "9" * 400 + " F100\nM30", NcErrorId.VALUE_OUT_OF_RANGE, 1, 4),
    ],
)
def test_motion_errors(program, err, line, column) -> None:
    e = error_of(program)
    assert (e.id, e.line, e.column) == (err, line, column), str(e)


def test_arc_error_message_names_both_radii() -> None:
    e = error_of("G1 X10 F100\nG3 X0 Y10.25 I-10\nM30")
    assert e.message == "arc end point is not on the circle (radius 10.000 vs 10.250)"


def test_error_in_an_arc_block_with_plane_axis_missing() -> None:
    e = error_of("G18 G1 X1 F100\nG2 X2 I1\nM30", axes=("X", "Y"))
    assert e.id == NcErrorId.PLANE_AXIS_MISSING


def test_compensation_and_tool_radius() -> None:
    blocks = decode("G1 X1 F100\nG41 D1 X2\nG42 D2 X3\nG40 X4\nD0 X5\nM30")
    got = [(b.motion.compensation, b.motion.tool_radius_mm) for b in blocks if b.motion]
    assert got == [
        (Compensation.OFF, 0.0), (Compensation.LEFT, 2.5), (Compensation.RIGHT, 1.0),
        (Compensation.OFF, 1.0), (Compensation.OFF, 0.0),
    ]


def test_zero_length_move_gives_a_block_without_motion() -> None:
    for text in ("G1 X0 F100\nN5 G0 X0\nM30", slow("G1 X0 F100\nN5 G0 X0\nM30")):
        blocks = decode(text)
        assert [b.motion for b in blocks[:2]] == [None, None]
        assert blocks[1].number == 5


def test_modal_only_blocks_give_no_block() -> None:
    blocks = decode("G90\nF100\nG17 G40\nD1\nN10\nG1 X1\nM30")
    assert len(blocks) == 2
    assert blocks[0].source.line == 6


@pytest.mark.parametrize(
    ("program", "plane", "centre", "end"),
    [
        # issue 39, ISG "Simple helical interpolation": the axis perpendicular to the plane
        # is the helix axis (G17: Z, G18: Y, G19: X); I/J/K and R give the plane's centre
        ("G1 X10 F100\nG2 X0 Y-10 Z-5 I-10 J0\nM30", (0, 1), (0, 0), (0, -10, -5)),
        ("G1 X10 F100\nG3 X0 Y10 Z2 R10\nM30", (0, 1), (0, 0), (0, 10, 2)),
        ("G1 X10 F100\nG2 I-10 Z-1.5\nM30", (0, 1), (0, 0), (10, 0, -1.5)),  # one turn
        ("G1 Z10 F100\nG18 G3 X10 Z0 Y4 K-10\nM30", (2, 0), (0, 0), (10, 4, 0)),
        ("G1 Y10 F100\nG19 G2 Y0 Z10 X-3 J-10\nM30", (1, 2), (0, 0), (-3, 0, 10)),
        ("G91 G1 X10 F100\nG3 X-10 Y10 Z-4 I-10\nM30", (0, 1), (0, 0), (0, 10, -4)),
    ],
)
def test_helical_arcs(program: str, plane: tuple[int, int], centre: tuple[float, float],
                      end: tuple[float, ...]) -> None:
    for text in (program, slow(program)):
        arc = motions(text)[-1]
        assert arc.plane == plane
        assert arc.center_mm == pytest.approx(tuple(map(float, centre)), abs=1e-12)
        assert arc.end_mm == pytest.approx(tuple(map(float, end)), abs=1e-12)


def test_helix_end_off_the_circle_is_the_plane_arcs_error() -> None:
    assert error_of("G1 F100\nG2 X20 Z-3 I6\nM30").id == NcErrorId.ARC_RADIUS_DIFFERENCE


def test_helix_axis_alone_needs_a_centre_and_is_then_one_turn() -> None:
    # only the helix axis programmed: without I/J/R the plane arc's missing-centre error,
    # with a centre one full turn (end = start in the plane)
    assert error_of("G1 X10 F100\nG2 Z-5\nM30").id == NcErrorId.MISSING_VALUE
    arc = motions("G1 X10 F100\nG2 Z-5 I-10\nM30")[-1]
    assert arc.end_mm == (10.0, 0.0, -5.0) and arc.center_mm == (0.0, 0.0)
