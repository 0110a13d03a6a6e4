"""The benchmark's reference optimum and its programs.

Hand-computed cases of the model, a cross-check against the kernel's own whole-program
planner (which the reference must agree with without sharing code), and the programs'
text decoded by the kernel's decoder against their independent geometry.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from bench import lookahead_programs as lp
from bench.reference_optimum import (
    Arc,
    AxisLimit,
    Line,
    axis_limits,
    optimum_time_s,
    plan,
    speed_at,
)
from cnc_objects.service.kernel.nc import Decoder
from cnc_objects.service.kernel.nc.blocks import Block, Motion, MotionKind, SourceRef
from cnc_objects.service.kernel.path import AxisDynamics, plan_time_optimal
from cnc_objects.service.kernel.path.planner import plan_profile

DEFAULT = (AxisLimit(500.0, 5000.0, 20.0),) * 3
ORIGIN = (0.0, 0.0, 0.0)
X10 = (10.0, 0.0, 0.0)
CORNER = [Line(ORIGIN, X10, 6000.0), Line(X10, (10.0, 10.0, 0.0), 6000.0)]  # X, then Y


@pytest.fixture(scope="module")
def programs() -> dict[str, lp.BenchProgram]:
    """The programs that are quick to build and decode (r = 20 and 5 chords are not)."""
    progs = [lp.spiral(), lp.pocket(), lp.alternating(), lp.circle_chords(1.0)]
    progs += [lp.circle_arcs(r) for r in lp.CIRCLE_RADII_MM]
    return {p.name: p for p in progs}


# --- hand-computed cases (default machine: V 500 mm/s, A 5000 mm/s^2, dV 20 mm/s) ---

def test_default_machine_limits() -> None:
    assert axis_limits() == DEFAULT


def test_short_line_is_a_triangle() -> None:
    # 1 mm at F6000: a L = 5000 < 100^2, so the peak is sqrt(a L) and t = 2 sqrt(L / a)
    [p] = plan([Line(ORIGIN, (1.0, 0.0, 0.0), 6000.0)], DEFAULT)
    assert p.v_peak_mm_s == pytest.approx(math.sqrt(5000.0), rel=1e-12)
    assert p.time_s == pytest.approx(2.0 * math.sqrt(1.0 / 5000.0), rel=1e-12)


def test_long_line_is_a_trapezoid() -> None:
    # 10 mm at 100 mm/s: 2 x 0.02 s ramps over 2 x 1 mm, 8 mm cruise at 100 mm/s
    [p] = plan([Line(ORIGIN, (0.0, 10.0, 0.0), 6000.0)], DEFAULT)
    assert (p.cap_mm_s, p.v_peak_mm_s, p.v_in_mm_s, p.v_out_mm_s) == (100.0, 100.0, 0.0, 0.0)
    assert p.time_s == pytest.approx(0.04 + 0.08, rel=1e-12)


def test_right_angle_corner_limited_by_velocity_jump() -> None:
    # X then Y: both axes change by 1, so the corner runs at dV = 20 mm/s
    first, second = plan(CORNER, DEFAULT)
    assert first.v_out_mm_s == second.v_in_mm_s == pytest.approx(20.0, rel=1e-12)
    # 0 -> 100 -> 20 mm/s: ramps (100 + 80) / 5000 s over (100^2 + 100^2 - 20^2) / 10000 mm
    one = (100.0 + 80.0) / 5000.0 + (10.0 - (2e4 - 400.0) / 1e4) / 100.0
    assert optimum_time_s(CORNER, DEFAULT) == pytest.approx(2.0 * one, rel=1e-12)


def test_corner_takes_the_smallest_axis_jump() -> None:
    limits = (AxisLimit(500.0, 5000.0, 20.0), AxisLimit(500.0, 5000.0, 6.0), DEFAULT[2])
    assert plan(CORNER, limits)[0].v_out_mm_s == pytest.approx(6.0, rel=1e-12)


def test_full_circle_limited_by_centripetal_acceleration() -> None:
    # r = 1 mm: a = 5000/sqrt(2), cap = sqrt(r a) < 100 mm/s; ramps take r = cap^2/a mm
    r, a = 1.0, 5000.0 / math.sqrt(2.0)
    [p] = plan([Arc(ORIGIN, ORIGIN, (r, 0.0), ccw=False, feed_mm_min=6000.0)], DEFAULT)
    assert (p.length_mm, p.acc_mm_s2) == (pytest.approx(2 * math.pi * r), pytest.approx(a))
    assert p.cap_mm_s == pytest.approx(math.sqrt(r * a), rel=1e-12)
    expected = 2.0 * math.sqrt(r / a) + (2.0 * math.pi - 1.0) * r / math.sqrt(r * a)
    assert p.time_s == pytest.approx(expected, rel=1e-12)


def test_quarter_arcs_sweep_in_their_sense() -> None:
    # from (10, 0) about the origin to (0, 10): G3 a quarter, G2 three quarters
    start, end = (10.0, 0.0, 0.0), (0.0, 10.0, 0.0)
    [ccw] = plan([Arc(start, end, (0.0, 0.0), ccw=True, feed_mm_min=600.0)], DEFAULT)
    [cw] = plan([Arc(start, end, (0.0, 0.0), ccw=False, feed_mm_min=600.0)], DEFAULT)
    assert ccw.length_mm == pytest.approx(5.0 * math.pi, rel=1e-12)
    assert cw.length_mm == pytest.approx(15.0 * math.pi, rel=1e-12)


def test_rapid_line_limited_by_axis_velocity_over_direction() -> None:
    # G0 along (0.6, 0.8): cap = 500/0.8 = 625 mm/s, a = 5000/0.8 = 6250 mm/s^2
    [p] = plan([Line(ORIGIN, (300.0, 400.0, 0.0), math.inf)], DEFAULT)
    assert (p.cap_mm_s, p.acc_mm_s2) == (pytest.approx(625.0), pytest.approx(6250.0))
    assert p.time_s == pytest.approx(2 * 625.0 / 6250.0 + (500.0 - 62.5) / 625.0, rel=1e-12)


def test_zero_length_elements_are_skipped() -> None:
    point = (10.0, 0.0, 0.0)
    elements = [Line(ORIGIN, point, 6000.0), Line(point, point, 6000.0),
                Line(point, (10.0, 10.0, 0.0), 6000.0)]
    planned = plan(elements, DEFAULT)
    assert [p.index for p in planned] == [0, 2]
    assert optimum_time_s(elements, DEFAULT) == optimum_time_s(elements[::2], DEFAULT)


def test_speed_at_follows_the_profile() -> None:
    planned = plan(CORNER, DEFAULT)
    s = np.array([-1.0, 0.0, 0.5, 5.0, 10.0, 19.5, 20.0, 30.0])
    v = speed_at(planned, s)
    expected = [0.0, 0.0, math.sqrt(5000.0), 100.0, 20.0, math.sqrt(5000.0), 0.0, 0.0]
    np.testing.assert_allclose(v, expected, rtol=1e-12, atol=1e-9)


# --- cross-check against the kernel's whole-program planner ---

def _kernel_blocks(elements) -> list[Block]:
    blocks = []
    for n, e in enumerate(elements, start=1):
        if isinstance(e, Arc):
            kind = MotionKind.ARC_CCW if e.ccw else MotionKind.ARC_CW
            motion = Motion(kind, e.start, e.end, e.feed_mm_min / 60.0, plane=e.plane,
                            center_mm=e.center)
        elif math.isinf(e.feed_mm_min):
            motion = Motion(MotionKind.RAPID, e.start, e.end, math.inf)
        else:
            motion = Motion(MotionKind.LINEAR, e.start, e.end, e.feed_mm_min / 60.0)
        blocks.append(Block(SourceRef("bench.nc", n), n, motion))
    return blocks


def _dynamics(limits) -> list[AxisDynamics]:
    return [AxisDynamics(lim.vel_max_mm_s, lim.acc_max_mm_s2, lim.vel_jump_mm_s) for lim in limits]


UNEVEN = (AxisLimit(400.0, 3000.0, 15.0), AxisLimit(500.0, 5000.0, 20.0),
          AxisLimit(300.0, 2000.0, 10.0))


@pytest.mark.parametrize("limits", [DEFAULT, UNEVEN], ids=["default", "uneven"])
@pytest.mark.parametrize("name", ["spiral", "pocket", "alternating", "circle_arcs_r1",
                                  "circle_arcs_r5", "circle_arcs_r20"])
def test_agrees_with_kernel_planner(programs, name, limits) -> None:
    elements = programs[name].elements
    blocks = _kernel_blocks(elements)
    kernel = plan_time_optimal(blocks, _dynamics(limits), ORIGIN)
    assert optimum_time_s(elements, limits) == pytest.approx(kernel, rel=1e-9)


def test_per_element_speeds_agree_with_kernel(programs) -> None:
    elements = programs["spiral"].elements
    ours = plan(elements, DEFAULT)
    theirs = plan_profile(_kernel_blocks(elements), _dynamics(DEFAULT), ORIGIN)
    assert len(ours) == len(theirs)
    np.testing.assert_allclose([p.v_out_mm_s for p in ours], [p.exit_mm_s for p in theirs],
                               rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose([p.v_peak_mm_s for p in ours], [p.peak_mm_s for p in theirs],
                               rtol=1e-9, atol=1e-9)


# --- the programs ---

def _decoded_motions(text: str, name: str) -> list[Motion]:
    def loader(file: str) -> str:
        raise KeyError(file)

    decoder = Decoder(text, f"{name}.nc", axes=("X", "Y", "Z"), loader=loader, tools={})
    return [b.motion for b in decoder.blocks() if b.motion is not None]


@pytest.mark.parametrize("name", ["spiral", "pocket", "alternating", "circle_chords_r1",
                                  "circle_arcs_r1", "circle_arcs_r5", "circle_arcs_r20"])
def test_text_decodes_to_the_elements(programs, name) -> None:
    program = programs[name]
    motions = _decoded_motions(program.text, name)
    assert len(motions) == len(program.elements) == program.blocks
    assert program.elements[0].start == ORIGIN  # the machine's start position
    for m, e in zip(motions, program.elements):
        assert math.dist(m.start_mm, e.start) <= 1e-9
        assert math.dist(m.end_mm, e.end) <= 1e-9
        assert m.feed_mm_s == e.feed_mm_min / 60.0
        if isinstance(e, Arc):
            assert m.kind == (MotionKind.ARC_CCW if e.ccw else MotionKind.ARC_CW)
            assert math.dist(m.center_mm, e.center) <= 1e-9
        else:
            assert m.kind == MotionKind.LINEAR


def test_block_counts(programs) -> None:
    assert programs["spiral"].blocks == 10_001
    assert programs["pocket"].blocks == 303
    assert programs["alternating"].blocks == 300
    assert programs["circle_chords_r1"].blocks == 2 * round(2 * math.pi / 0.001)
    assert all(programs[f"circle_arcs_r{r:g}"].blocks == 2 for r in lp.CIRCLE_RADII_MM)


def test_spiral_segments_are_50_um(programs) -> None:
    lengths = [math.dist(e.start, e.end) for e in programs["spiral"].elements[1:]]
    assert max(abs(x - 0.05) for x in lengths) < 2e-9  # printed to 1e-9 mm


def _turns_deg(elements) -> set[float]:
    """Direction changes at the junctions, rounded to 1e-4 degree (coordinates printed to
    1e-9 mm turn a 0.01 mm line by up to 1e-7 rad)."""
    out = set()
    for a, b in zip(elements, elements[1:]):
        ua = np.subtract(a.end, a.start) / math.dist(a.start, a.end)
        ub = np.subtract(b.end, b.start) / math.dist(b.start, b.end)
        out.add(round(math.degrees(math.acos(np.clip(ua @ ub, -1.0, 1.0))), 4))
    return out


def test_pocket_has_90_30_and_150_degree_corners(programs) -> None:
    assert _turns_deg(programs["pocket"].elements) == {90.0, 30.0, 150.0}


def test_alternating_blocks(programs) -> None:
    elements = programs["alternating"].elements
    lengths = [math.dist(e.start, e.end) for e in elements]
    np.testing.assert_allclose(lengths, [0.01, 10.0] * 150, atol=2e-9)
    assert _turns_deg(elements) == {8.0}


def test_chords_are_1_um_on_the_circle(programs) -> None:
    elements = programs["circle_chords_r1"].elements
    lengths = [math.dist(e.start, e.end) for e in elements]
    # 6283 chords per circle: 2 sin(pi / 6283) mm = 0.99997 um each
    assert max(abs(x - 2.0 * math.sin(math.pi / 6283)) for x in lengths) < 2e-9
    assert max(abs(math.dist(e.end[:2], (1.0, 0.0)) - 1.0) for e in elements) < 1e-9
    assert elements[6282].end == elements[-1].end == ORIGIN  # each circle closes at the origin


def test_with_la_on_wraps_the_motion_blocks(programs) -> None:
    lines = lp.with_la_on(programs["circle_arcs_r5"].text).split("\n")
    assert lines[1:3] == ["LA_ON", "N10 G02 X0.000000000 Y0.000000000 I5.000000000 "
                                   "J0.000000000 F6000"]
    assert lines[-3:] == ["LA_OFF", "N30 M30", ""]
