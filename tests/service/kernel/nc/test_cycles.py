"""ISG cycles through the decoder (CYCLES-ADC): the calculation cycles, user cycles,
SysHscSettings and the syntax check of cycle calls.

The programming examples of the cycle documentation are run character for character
(only the code-fence markers of the PDF export are left out)."""

from __future__ import annotations

import math
from decimal import Decimal
from itertools import islice

import numpy as np
import pytest

from cnc_objects.service.kernel.nc import MotionKind, NcErrorId
from cnc_objects.service.kernel.nc.check import ErrorCategory
from cnc_objects.service.kernel.nc.modal import DistanceMode, Plane
from cnc_objects.service.kernel.nc.technology import HscProgram
from tests.support.check_mode import Recorder, Run

from .cycle_support import Channel, assert_at, where

E = NcErrorId
def lit(value: float) -> str:
    """An NC number literal that reads back exactly (no exponent)."""
    return format(Decimal(repr(float(value))), "f")


def motion_blocks(blocks):
    return [b for b in blocks if b.motion is not None]


# ---------------------------------------------------------------- 1. the documentation examples

CIRCLE_EXAMPLE = '; Definition of return variables\n#VAR\n  V.CYC.SysRetRadius\n  V.CYC.SysRetCenterX\n  V.CYC.SysRetCenterY\n  V.CYC.SysRetVariance\n#ENDVAR\n\n; cycle call\nL CYCLE [NAME=SysCalcCircle.ecy \\\n@P50 = 0 @P60 = -1 \\\n@P51 = 0 @P61 = 1 \\\n@P52 = 1 @P62 = 0 \\\n@P53 = -1 @P63 = 0 ]\n\n; print result\n#FILE NAME [MSG="SysCalcCircleResult.txt"]\n\n#MSG SAVE EXCLUSIVE["Center X = %f",V.CYC.SysRetCenterX]\n#MSG SAVE EXCLUSIVE["Center Y = %f",V.CYC.SysRetCenterY]\n#MSG SAVE EXCLUSIVE["Radius = %f", V.CYC.SysRetRadius]\n#MSG SAVE EXCLUSIVE["Variance = %f", V.CYC.SysRetVariance]\n\nM30\n'  # noqa: E501

PLANE_EXAMPLE = '; creation of return variables\n#VAR\n  V.CYC.SysRetNormalX\n  V.CYC.SysRetNormalY\n  V.CYC.SysRetNormalZ\n  V.CYC.SysRetSupVectorX\n  V.CYC.SysRetSupVectorY\n  V.CYC.SysRetSupVectorZ\n#ENDVAR\n\n; calculation of the XY plane\nL CYCLE [NAME=SysCalcPlane.ecy \\\n@P50 = 1 @P60 = 0 @P70 = 0 \\\n@P51 = 0 @P61 = 1 @P71 = 0 \\\n@P52 = 1 @P62 = 1 @P72 = 0 ]\n\n; print result\n#FILE NAME[MSG="SysCalcPlaneResult.txt" ]\n#MSG SAVE ["Normal X = %f", V.CYC.SysRetNormalX ]\n#MSG SAVE ["Normal Y = %f", V.CYC.SysRetNormalY ]\n#MSG SAVE ["Normal Z = %f", V.CYC.SysRetNormalZ ]\n#MSG SAVE ["Point X = %f", V.CYC.SysRetSupVectorX ]\n#MSG SAVE ["Point Y = %f", V.CYC.SysRetSupVectorY ]\n#MSG SAVE ["Point Z = %f", V.CYC.SysRetSupVectorZ ]\n\nM30\n'  # noqa: E501

LINE_EXAMPLE = '; creation of return variables\n#VAR\n  V.CYC.SysRetDirVectorX\n  V.CYC.SysRetDirVectorY\n  V.CYC.SysRetDirVectorZ\n  V.CYC.SysRetSupVectorX\n  V.CYC.SysRetSupVectorY\n  V.CYC.SysRetSupVectorZ\n  V.CYC.SysRetVariance\n#ENDVAR\n\n; calc line of X-axis from points\nL CYCLE [NAME=SysCalcLine.ecy \\\n@P50 = 0 @P60 = 0 @P70 = 0 \\\n@P51 = 1 @P61 = 0 @P71 = 0 \\\n@P52 = 2 @P62 = 0 @P72 = 0 \\\n]\n\n#FILE NAME[MSG="SysCalcLineResult.txt" ]\n#MSG SAVE ["Direction X = %f", V.CYC.SysRetDirVectorX]\n#MSG SAVE ["Direction Y = %f", V.CYC.SysRetDirVectorY]\n#MSG SAVE ["Direction Z = %f", V.CYC.SysRetDirVectorZ]\n#MSG SAVE ["Point on Line X = %f", V.CYC.SysRetSupVectorX]\n#MSG SAVE ["Point on Line Y = %f", V.CYC.SysRetSupVectorY]\n#MSG SAVE ["Point on Line Z = %f", V.CYC.SysRetSupVectorZ]\n#MSG SAVE ["Variance = %f", V.CYC.SysRetVariance ]\n\nM30\n'  # noqa: E501

SPHERE_EXAMPLE = '; creation of return variables\n#VAR\n  V.CYC.SysRetCenterX\n  V.CYC.SysRetCenterY\n  V.CYC.SysRetCenterZ\n  V.CYC.SysRetRadius\n  V.CYC.SysRetVariance\n#ENDVAR\n\n; calculation of the unit sphere\nL CYCLE [NAME=SysCalcSphere.ecy \\\n@P50 = 1 @P60 = 0 @P70 = 0 \\\n@P51 = -1 @P61 = 0 @P71 = 0 \\\n@P52 = 0 @P62 = 1 @P72 = 0 \\\n@P53 = 0 @P63 = -1 @P73 = 0 \\\n@P54 = 0 @P64 = 0 @P74 = 1 \\\n]\n\n; print result\n#FILE NAME [MSG="SysCalcSphereResult.txt"]\n#MSG SAVE EXCLUSIVE["Center X = %f", V.CYC.SysRetCenterX ]\n#MSG SAVE EXCLUSIVE["Center Y = %f", V.CYC.SysRetCenterY ]\n#MSG SAVE EXCLUSIVE["Center Z = %f", V.CYC.SysRetCenterZ ]\n#MSG SAVE EXCLUSIVE["Radius = %f", V.CYC.SysRetRadius ]\n#MSG SAVE EXCLUSIVE["Variance = %f", V.CYC.SysRetVariance]\n\nM30\n'  # noqa: E501

PLANE_CIRCLE_EXAMPLE = '; creation of return variables\n#VAR\n  V.CYC.SysRetCenterX\n  V.CYC.SysRetCenterY\n  V.CYC.SysRetCenterZ\n  V.CYC.SysRetNormalX\n  V.CYC.SysRetNormalY\n  V.CYC.SysRetNormalZ\n  V.CYC.SysRetRadius\n  V.CYC.SysRetRadVariance\n#ENDVAR\n\n; calculation of unit circle in the XY-plane with Z=1\nL CYCLE [NAME=SysCalcPlaneCircle.ecy \\\n@P50 = 1 @P60 = 0 @P70 = 1 \\\n@P51 = 0 @P61 = 1 @P71 = 1 \\\n@P52 = -1 @P62 = 0 @P72 = 1 \\\n\n@P53 = 0 @P63 = -1 @P73 = 1      ]  \n  \n; print result  \n#FILE NAME[MSG="SysCalcPlaneCircleResult.txt"      ]  \n#MSG SAVE ["Radius    = %f", V.CYC.SysRetRadius    ]  \n#MSG SAVE ["Center X = %f", V.CYC.SysRetCenterX   ]  \n#MSG SAVE ["Center Y = %f", V.CYC.SysRetCenterY   ]  \n#MSG SAVE ["Center Z = %f", V.CYC.SysRetCenterZ   ]  \n#MSG SAVE ["Normal X = %f", V.CYC.SysRetNormalX   ]  \n#MSG SAVE ["Normal Y = %f", V.CYC.SysRetNormalY   ]  \n#MSG SAVE ["Normal Z = %f", V.CYC.SysRetNormalZ   ]  \n#MSG SAVE ["Variance = %f", V.CYC.SysRetRadVariance ]  \n  \nM30\n'  # noqa: E501

CIRCLE_RESULT = "Center X = 0.000000\nCenter Y = 0.000000\nRadius = 1.000000\nVariance = 0.000000\n"
PLANE_RESULT = ("Normal X = 0.000000\nNormal Y = 0.000000\nNormal Z = 1.000000\n"
                "Point X = 0.666667\nPoint Y = 0.666667\nPoint Z = 0.000000\n")
LINE_RESULT = ("Direction X = 1.000000\nDirection Y = 0.000000\nDirection Z = 0.000000\n"
               "Point on Line X = 1.000000\nPoint on Line Y = 0.000000\n"
               "Point on Line Z = 0.000000\nVariance = 0.000000\n")
SPHERE_RESULT = ("Center X = 0.000000\nCenter Y = 0.000000\nCenter Z = 0.000000\n"
                 "Radius = 1.000000\nVariance = 0.000000\n")
PLANE_CIRCLE_RESULT = ("Radius    = 1.000000\nCenter X = 0.000000\nCenter Y = 0.000000\n"
                       "Center Z = 1.000000\nNormal X = 0.000000\nNormal Y = 0.000000\n"
                       "Normal Z = 1.000000\nVariance = 0.000000\n")

OLD = "old content of the file\n"


@pytest.mark.parametrize("program, file, result", [
    (CIRCLE_EXAMPLE, "SysCalcCircleResult.txt", CIRCLE_RESULT),
    (SPHERE_EXAMPLE, "SysCalcSphereResult.txt", SPHERE_RESULT),
], ids=["SysCalcCircle", "SysCalcSphere"])
def test_exclusive_examples_replace_the_old_file(program, file, result) -> None:
    channel = Channel({file: OLD})
    d, blocks = channel.run(program)
    assert channel.files[file] == result  # the old content is gone
    # the first EXCLUSIVE line replaces, the following ones append
    replaces = [replace for name, _, replace in channel.writes if name == file]
    assert replaces == [True] + [False] * (result.count("\n") - 1)
    assert len(blocks) == 1 and blocks[0].motion is None  # only M30: a calculation moves nothing
    assert channel.messages == []
    # a second run of the program (a new program start) replaces the file again
    channel.run(program)
    assert channel.files[file] == result


@pytest.mark.parametrize("program, file, result", [
    (PLANE_EXAMPLE, "SysCalcPlaneResult.txt", PLANE_RESULT),
    (LINE_EXAMPLE, "SysCalcLineResult.txt", LINE_RESULT),
    (PLANE_CIRCLE_EXAMPLE, "SysCalcPlaneCircleResult.txt", PLANE_CIRCLE_RESULT),
], ids=["SysCalcPlane", "SysCalcLine", "SysCalcPlaneCircle"])
def test_examples_without_exclusive_append_to_the_file(program, file, result) -> None:
    channel = Channel({file: OLD})
    channel.run(program)
    assert channel.files[file] == OLD + result
    assert all(not replace for name, _, replace in channel.writes if name == file)
    channel.run(program)
    assert channel.files[file] == OLD + result + result


def test_examples_write_a_new_file_when_there_is_none() -> None:
    channel = Channel()
    for program in (CIRCLE_EXAMPLE, PLANE_EXAMPLE, LINE_EXAMPLE, SPHERE_EXAMPLE,
                    PLANE_CIRCLE_EXAMPLE):
        channel.run(program)
    assert channel.files == {
        "SysCalcCircleResult.txt": CIRCLE_RESULT, "SysCalcPlaneResult.txt": PLANE_RESULT,
        "SysCalcLineResult.txt": LINE_RESULT, "SysCalcSphereResult.txt": SPHERE_RESULT,
        "SysCalcPlaneCircleResult.txt": PLANE_CIRCLE_RESULT,
    }


def test_exclusive_replaces_once_per_file_and_run() -> None:
    channel = Channel({"a.txt": "old a\n", "b.txt": "old b\n"})
    channel.run('#FILE NAME [MSG="a.txt"]\n#MSG SAVE EXCLUSIVE ["a1"]\n'
                '#FILE NAME [MSG="b.txt"]\n#MSG SAVE EXCLUSIVE ["b1"]\n'
                '#FILE NAME [MSG="a.txt"]\n#MSG SAVE EXCLUSIVE ["a2"]\n#MSG SAVE ["a3"]\nM30\n')
    assert channel.files == {"a.txt": "a1\na2\na3\n", "b.txt": "b1\n"}


def test_outputs_of_the_example_are_in_the_callers_variables() -> None:
    # the documentation example, checked in the program itself: an error if wrong
    text = CIRCLE_EXAMPLE.replace(
        "M30\n", "$IF V.CYC.SysRetRadius <> 1 OR V.CYC.SysRetCenterX <> 0 OR "
                 "V.CYC.SysRetCenterY <> 0 OR V.CYC.SysRetVariance > 0.000000000001\n"
                 "G01 X[1/0]\n$ENDIF\nG01 F100 X[V.CYC.SysRetRadius * 7]\nM30\n")
    _, blocks = Channel().run(text)
    (move,) = motion_blocks(blocks)
    assert move.motion.end_mm == pytest.approx((7.0, 0.0, 0.0), abs=1e-12)


def test_outputs_not_declared_are_no_error() -> None:
    text = "L CYCLE [NAME=SysCalcCircle.ecy @P50=0 @P60=-1 @P51=0 @P61=1 @P52=1 @P62=0]\nM30\n"
    _, blocks = Channel().run(text)
    assert len(blocks) == 1


# ---------------------------------------------------------------- 2. exact fits through the NC call

def fit_program(cycle: str, points, outputs) -> str:
    dims = len(points[0])
    params = " \\\n".join(" ".join(f"@P{50 + 10 * d + k}={lit(points[k][d])}" for d in range(dims))
                          for k in range(len(points)))
    declared = "\n".join(f"V.CYC.{name}" for name in outputs)
    saves = "\n".join(f'#MSG SAVE ["{name}=%.15e", V.CYC.{name}]' for name in outputs)
    return (f"#VAR\n{declared}\n#ENDVAR\nL CYCLE [NAME={cycle} \\\n{params} \\\n]\n"
            f'#FILE NAME [MSG="fit.txt"]\n{saves}\nM30\n')


def fitted(cycle: str, points, outputs) -> dict[str, float]:
    channel = Channel()
    channel.run(fit_program(cycle, points, outputs))
    values = dict(line.split("=") for line in channel.files["fit.txt"].splitlines())
    assert list(values) == list(outputs)
    return {name: float(v) for name, v in values.items()}


def test_circle_on_a_partial_arc() -> None:
    cx, cy, r = 12.5, -7.25, 37.5
    points = [(cx + r * math.cos(math.radians(a)), cy + r * math.sin(math.radians(a)))
              for a in (10, 35, 60, 85, 110)]
    out = fitted("SysCalcCircle.ecy", points,
                 ("SysRetCenterX", "SysRetCenterY", "SysRetRadius", "SysRetVariance"))
    assert out["SysRetCenterX"] == pytest.approx(cx, abs=1e-9)
    assert out["SysRetCenterY"] == pytest.approx(cy, abs=1e-9)
    assert out["SysRetRadius"] == pytest.approx(r, abs=1e-9)
    assert 0.0 <= out["SysRetVariance"] < 1e-9


def test_circle_variance_of_points_off_the_circle() -> None:
    # four points at radius 9 and 11 alternating: centre 0, radius 10, variance 1
    points = [(9.0, 0.0), (0.0, 11.0), (-9.0, 0.0), (0.0, -11.0)]
    out = fitted("SysCalcCircle.ecy", points,
                 ("SysRetCenterX", "SysRetCenterY", "SysRetRadius", "SysRetVariance"))
    assert (out["SysRetCenterX"], out["SysRetCenterY"]) == pytest.approx((0.0, 0.0), abs=1e-9)
    assert out["SysRetRadius"] == pytest.approx(10.0, abs=1e-9)
    assert out["SysRetVariance"] == pytest.approx(1.0, abs=1e-9)


def test_tilted_plane() -> None:
    normal = np.array([1.0, 2.0, 2.0]) / 3.0
    u = np.array([2.0, -1.0, 0.0]) / math.sqrt(5.0)
    v = np.cross(normal, u)
    origin = np.array([4.0, -3.0, 7.0])
    points = [tuple(float(c) for c in origin + s * u + t * v)
              for s, t in ((0, 0), (10, 0), (0, 6), (-4, 3), (7, -5))]
    out = fitted("SysCalcPlane.ecy", points,
                 ("SysRetNormalX", "SysRetNormalY", "SysRetNormalZ",
                  "SysRetSupVectorX", "SysRetSupVectorY", "SysRetSupVectorZ"))
    n = np.array([out[f"SysRetNormal{a}"] for a in "XYZ"])
    support = np.array([out[f"SysRetSupVector{a}"] for a in "XYZ"])
    assert n == pytest.approx(normal, abs=1e-9)  # unit, with positive Z
    assert abs(float(np.dot(support - origin, normal))) < 1e-9  # a point on the plane
    assert support == pytest.approx(np.mean(points, axis=0), abs=1e-9)  # the centroid


def test_plane_normal_points_to_positive_z_whatever_the_point_order() -> None:
    points = [(0.0, 0.0, 0.0), (0.0, 1.0, 1.0), (1.0, 0.0, 0.0)]  # clockwise seen from +Z
    out = fitted("SysCalcPlane.ecy", points, ("SysRetNormalX", "SysRetNormalY", "SysRetNormalZ"))
    s = math.sqrt(0.5)
    assert (out["SysRetNormalX"], out["SysRetNormalY"], out["SysRetNormalZ"]) == \
        pytest.approx((0.0, -s, s), abs=1e-9)


def test_line_in_space() -> None:
    direction = np.array([3.0, -4.0, 12.0]) / 13.0
    base = np.array([1.0, 2.0, 3.0])
    points = [tuple(float(c) for c in base + t * direction) for t in (-2.0, 0.5, 3.0, 7.0)]
    names = ("SysRetDirVectorX", "SysRetDirVectorY", "SysRetDirVectorZ",
             "SysRetSupVectorX", "SysRetSupVectorY", "SysRetSupVectorZ", "SysRetVariance")
    out = fitted("SysCalcLine.ecy", points, names)
    d = np.array([out[f"SysRetDirVector{a}"] for a in "XYZ"])
    support = np.array([out[f"SysRetSupVector{a}"] for a in "XYZ"])
    assert d == pytest.approx(direction, abs=1e-9)  # from the first toward the last point
    off = (support - base) - np.dot(support - base, direction) * direction
    assert np.linalg.norm(off) < 1e-9  # the support point lies on the line
    assert 0.0 <= out["SysRetVariance"] < 1e-9
    # the same points in reverse order: the direction turns round
    reverse = fitted("SysCalcLine.ecy", points[::-1], names[:3])
    assert np.array([reverse[f"SysRetDirVector{a}"] for a in "XYZ"]) == \
        pytest.approx(-direction, abs=1e-9)


def test_line_through_two_points() -> None:
    out = fitted("SysCalcLine.ecy", [(1.0, 1.0, 1.0), (1.0, 1.0, -4.0)],
                 ("SysRetDirVectorX", "SysRetDirVectorY", "SysRetDirVectorZ", "SysRetSupVectorZ"))
    assert (out["SysRetDirVectorX"], out["SysRetDirVectorY"], out["SysRetDirVectorZ"]) == \
        pytest.approx((0.0, 0.0, -1.0), abs=1e-12)
    assert out["SysRetSupVectorZ"] == pytest.approx(-1.5, abs=1e-12)


def test_sphere() -> None:
    centre = np.array([3.0, -4.0, 5.5])
    r = 7.25
    dirs = [(1, 0.2, 0.1), (-0.3, 1, 0.5), (0.2, -0.4, 1), (-1, -0.5, 0.3), (0.6, 0.7, -0.9),
            (-0.2, 0.1, -1)]
    points = [tuple(float(c) for c in centre + r * np.array(dv) / np.linalg.norm(dv))
              for dv in dirs]
    out = fitted("SysCalcSphere.ecy", points,
                 ("SysRetCenterX", "SysRetCenterY", "SysRetCenterZ", "SysRetRadius",
                  "SysRetVariance"))
    assert np.array([out[f"SysRetCenter{a}"] for a in "XYZ"]) == pytest.approx(centre, abs=1e-9)
    assert out["SysRetRadius"] == pytest.approx(r, abs=1e-9)
    assert 0.0 <= out["SysRetVariance"] < 1e-9


def test_circle_in_space_on_a_partial_arc() -> None:
    centre = np.array([10.0, 20.0, 30.0])
    normal = np.array([0.0, 0.6, 0.8])
    e1 = np.array([1.0, 0.0, 0.0])
    e2 = np.cross(normal, e1)
    r = 4.0
    points = [tuple(float(c) for c in centre + r * (math.cos(math.radians(a)) * e1
                                                     + math.sin(math.radians(a)) * e2))
              for a in (0, 50, 95, 140, 200)]
    out = fitted("SysCalcPlaneCircle.ecy", points,
                 ("SysRetCenterX", "SysRetCenterY", "SysRetCenterZ", "SysRetRadius",
                  "SysRetNormalX", "SysRetNormalY", "SysRetNormalZ", "SysRetRadVariance"))
    assert np.array([out[f"SysRetCenter{a}"] for a in "XYZ"]) == pytest.approx(centre, abs=1e-9)
    assert np.array([out[f"SysRetNormal{a}"] for a in "XYZ"]) == pytest.approx(normal, abs=1e-9)
    assert out["SysRetRadius"] == pytest.approx(r, abs=1e-9)
    assert 0.0 <= out["SysRetRadVariance"] < 1e-9


def test_ten_points_are_accepted() -> None:
    points = [(5 + 2 * math.cos(k * 0.6), -1 + 2 * math.sin(k * 0.6)) for k in range(10)]
    out = fitted("SysCalcCircle.ecy", points, ("SysRetCenterX", "SysRetCenterY", "SysRetRadius"))
    assert (out["SysRetCenterX"], out["SysRetCenterY"], out["SysRetRadius"]) == \
        pytest.approx((5.0, -1.0, 2.0), abs=1e-9)


# ---------------------------------------------------------------- 3. errors of calls

@pytest.mark.parametrize("cycle, points, err_id", [
    ("SysCalcCircle.ecy", [(1, 1), (1, 1), (1, 1)], E.CYCLE_POINTS_IDENTICAL),
    ("SysCalcCircle.ecy", [(0, 0), (1, 2), (2, 4), (-3, -6)], E.CYCLE_POINTS_COLLINEAR),
    ("SysCalcPlane.ecy", [(1, 2, 3), (2, 3, 4), (4, 5, 6)], E.CYCLE_POINTS_COLLINEAR),
    ("SysCalcPlane.ecy", [(1, 2, 3)] * 3, E.CYCLE_POINTS_IDENTICAL),
    ("SysCalcLine.ecy", [(1, 2, 3), (1, 2, 3)], E.CYCLE_POINTS_IDENTICAL),
    ("SysCalcSphere.ecy", [(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0)], E.CYCLE_POINTS_COPLANAR),
    ("SysCalcSphere.ecy", [(1, 0, 0), (2, 0, 0), (3, 0, 0), (4, 0, 0)], E.CYCLE_POINTS_COLLINEAR),
    ("SysCalcPlaneCircle.ecy", [(0, 0, 1), (1, 1, 1), (2, 2, 1)], E.CYCLE_POINTS_COLLINEAR),
])
def test_degenerate_points(cycle, points, err_id) -> None:
    text = "G01 F100 X1\n" + fit_program(cycle, points, ("SysRetRadius",))
    error = Channel().error(text)
    assert int(err_id) in (20516, 20517, 20518)
    assert_at(error, err_id, text, cycle)  # at the call (its NAME)
    assert cycle in error.message


def test_degenerate_points_error_stops_before_the_rest() -> None:
    text = ('#FILE NAME [MSG="r.txt"]\n#MSG SAVE ["before"]\n'
            "L CYCLE [NAME=SysCalcCircle.ecy @P50=0 @P60=0 @P51=1 @P61=1 @P52=2 @P62=2]\n"
            '#MSG SAVE ["after"]\nM30\n')
    channel = Channel()
    error = channel.error(text)
    assert error.id == E.CYCLE_POINTS_COLLINEAR and error.line == 3
    assert channel.files == {"r.txt": "before\n"}


def test_two_points_are_too_few_for_a_circle() -> None:
    text = "L CYCLE [NAME=SysCalcCircle.ecy @P50=0 @P60=0 @P51=1 @P61=1]\nM30\n"
    error = Channel().error(text)
    assert_at(error, E.CYCLE_PARAMETER_MISSING, text, "SysCalcCircle.ecy")
    assert "@P52" in error.message and "point 3" in error.message


def test_one_point_is_too_few_for_a_line() -> None:
    text = "L CYCLE [NAME=SysCalcLine.ecy @P50=0 @P60=0 @P70=0]\nM30\n"
    error = Channel().error(text)
    assert error.id == E.CYCLE_PARAMETER_MISSING and "@P51" in error.message


def test_point_without_one_of_its_coordinates() -> None:
    text = "L CYCLE [NAME=SysCalcPlane.ecy @P50=0 @P60=0 @P70=0 @P51=1 @P61=0 @P71=0 " \
           "@P52=0 @P72=1]\nM30\n"
    error = Channel().error(text)
    assert error.id == E.CYCLE_PARAMETER_MISSING
    assert "@P62" in error.message and "point 3" in error.message


def test_unknown_parameter_of_the_2d_circle() -> None:
    text = "L CYCLE [NAME=SysCalcCircle.ecy @P50=0 @P60=0 @P51=1 @P61=1 @P52=2 @P62=1 @P70=1]\nM30\n"
    error = Channel().error(text)
    assert_at(error, E.CYCLE_PARAMETER_UNKNOWN, text, "@P70")
    assert "@P70" in error.message


def test_string_value_is_out_of_range() -> None:
    text = 'L CYCLE [NAME=SysCalcCircle.ecy @P50=0 @P60=0 @P51=1 @P61=1 @P52="two" @P62=1]\nM30\n'
    error = Channel().error(text)
    assert_at(error, E.CYCLE_PARAMETER_RANGE, text, "@P52")
    assert "@P52" in error.message and "string" in error.message


def test_point_five_without_point_four() -> None:
    text = ("L CYCLE [NAME=SysCalcCircle.ecy @P50=0 @P60=0 @P51=1 @P61=1 @P52=2 @P62=1 "
            "@P54=3 @P64=3]\nM30\n")
    error = Channel().error(text)
    assert error.id == E.CYCLE_PARAMETER_MISSING
    assert "@P53" in error.message and "point 4" in error.message
    assert (error.file, error.line) == ("prog.nc", 1)


def test_unknown_cycle_name() -> None:
    text = "G01 F100 X1\nL CYCLE [NAME=SysCalcEllipse.ecy @P50=0]\nM30\n"
    error = Channel().error(text)
    assert_at(error, E.CYCLE_NOT_FOUND, text, "SysCalcEllipse.ecy")
    assert "SysCalcEllipse.ecy" in error.message


def test_parameter_given_twice() -> None:
    text = "L CYCLE [NAME=SysCalcCircle.ecy @P50=0 @P60=0 @P50=1]\nM30\n"
    error = Channel().error(text)
    assert_at(error, E.CYCLE_PARAMETER_TWICE, text, "@P50", occurrence=1)
    assert "@P50" in error.message


def test_name_given_twice() -> None:
    text = "L CYCLE [NAME=a.ecy NAME=b.ecy]\nM30\n"
    error = Channel({"a.ecy": "M17\n", "b.ecy": "M17\n"}).error(text)
    assert_at(error, E.CYCLE_PARAMETER_TWICE, text, "NAME", occurrence=1)


@pytest.mark.parametrize("call, needle", [
    ("L CYCLE [@P50=0 @P60=0]", "L CYCLE"),  # no NAME
    ("L CYCLE [NAME=SysCalcCircle.ecy @P50=0 @P60=0", "["),  # no ']'
    ("L CYCLE [NAME= ]", "]"),  # empty name
    ("L CYCLE [NAME=SysCalcCircle.ecy @P50 0]", "0]"),  # no '='
    ("L CYCLE [NAME=SysCalcCircle.ecy FOO=1]", "FOO"),  # unknown keyword
])
def test_malformed_call(call, needle) -> None:
    text = f"G01 F100 X1\n{call}\nM30\n"
    error = Channel().error(text)
    assert_at(error, E.CYCLE_SYNTAX, text, needle)


def test_missing_bracket_of_a_continued_call_points_at_the_open_bracket() -> None:
    text = "L CYCLE [NAME=SysCalcCircle.ecy \\\n @P50=0 @P60=0 \\\n @P51=1 @P61=1\nM30\n"
    error = Channel().error(text)
    assert_at(error, E.CYCLE_SYNTAX, text, "[")


def test_error_in_a_continuation_line_points_at_its_physical_line() -> None:
    text = ("G01 F100\nL CYCLE [NAME=SysCalcCircle.ecy \\\n  ; first point\n"
            "  @P50=0 @P60=0 \\\n\n  ( second ) @P51=1 @P61=1 \\\n  @P52=2 @P62=\"s\" \\\n]\nM30\n")
    error = Channel().error(text)
    assert_at(error, E.CYCLE_PARAMETER_RANGE, text, "@P62")
    assert error.line == 7


def test_output_variable_of_a_wrong_type_is_the_programs_error() -> None:
    # (was a decoder fault, INTERNAL_ERROR, at the line after the call)
    text = ("#VAR\nV.CYC.SysRetCenterX : UNS08\n#ENDVAR\n"
            "L CYCLE [NAME=SysCalcCircle.ecy @P50=-5 @P60=0 @P51=-3 @P61=2 @P52=-1 @P62=0]\nM30\n")
    error = Channel().error(text)
    assert_at(error, E.VALUE_OUT_OF_TYPE_RANGE, text, "SysCalcCircle.ecy")
    assert "SYSRETCENTERX" in error.message.upper()
    text = ("#VAR\nV.CYC.SysRetRadius : STRING\n#ENDVAR\n"
            "L CYCLE [NAME=SysCalcCircle.ecy @P50=-5 @P60=0 @P51=-3 @P61=2 @P52=-1 @P62=0]\nM30\n")
    assert_at(Channel().error(text), E.TYPE_MISMATCH, text, "SysCalcCircle.ecy")


def test_integer_output_variable_gets_the_rounded_result() -> None:
    text = ("#VAR\nV.CYC.SysRetRadius : UNS08\n#ENDVAR\n"
            "L CYCLE [NAME=SysCalcCircle.ecy @P50=-5 @P60=0 @P51=-3 @P61=2 @P52=-1 @P62=0]\n"
            '#FILE NAME [MSG="r.txt"]\n#MSG SAVE ["%f", V.CYC.SysRetRadius]\nM30\n')
    channel = Channel()
    channel.run(text)
    assert channel.files["r.txt"] == "2.000000\n"


# ---------------------------------------------------------------- 4. how parameters are written

def test_parameters_as_expressions_and_variables() -> None:
    text = """#VAR
  V.L.R = 5
  V.L.CX = 2
  V.CYC.SysRetRadius
  V.CYC.SysRetCenterX
  V.CYC.SysRetCenterY
#ENDVAR
L CYCLE [ NAME = "SysCalcCircle.ecy" \\
; the first point
  @P50 = V.L.CX + V.L.R   @P60 = 3 \\

  ( the second point )
  @P51 = V.L.CX           @P61 = 3 + V.L.R \\
  @P52 = V.L.CX - V.L.R   @P62 = SQRT[9] * [1 + 0] \\
  ]
#FILE NAME [MSG="r.txt"]
#MSG SAVE ["%.9f %.9f %.9f", V.CYC.SysRetCenterX, V.CYC.SysRetCenterY, V.CYC.SysRetRadius]
M30
"""
    channel = Channel()
    channel.run(text)
    assert channel.files["r.txt"] == "2.000000000 3.000000000 5.000000000\n"


def test_cycle_names_are_case_insensitive_and_spaced() -> None:
    for name in ("syscalccircle.ecy", " SYSCALCCIRCLE.ECY", '"SysCalcCircle.ecy"'):
        text = (f"#VAR\nV.CYC.SysRetRadius\n#ENDVAR\nL CYCLE [NAME ={name} @P50 = 0 @P60 = -2 "
                "@P51 = 0 @P61 = 2 @P52 = 2 @P62 = 0]\n"
                '#FILE NAME [MSG="r.txt"]\n#MSG SAVE EXCLUSIVE ["%g", V.CYC.SysRetRadius]\nM30\n')
        channel = Channel()
        channel.run(text)
        assert channel.files["r.txt"] == "2\n", name


def test_parameter_values_are_evaluated_in_the_caller() -> None:
    files = {"show.ecy": '#MSG SAVE ["%g %s", @P1, @P2]\nM17\n'}
    text = ('#VAR\nV.L.A = 21\nV.L.S : STRING = "text"\n#ENDVAR\n#FILE NAME [MSG="r.txt"]\n'
            "L CYCLE [NAME=show.ecy @P1 = V.L.A * 2 @P2 = V.L.S]\nV.L.A = 0\nM30\n")
    channel = Channel(files)
    channel.run(text)
    assert channel.files["r.txt"] == "42 text\n"


def test_undeclared_variable_in_a_parameter() -> None:
    text = "L CYCLE [NAME=SysCalcCircle.ecy @P50 = V.L.NOPE]\nM30\n"
    error = Channel().error(text)
    assert error.id == E.UNDECLARED_VARIABLE and error.line == 1


# ---------------------------------------------------------------- 5. user cycles

USER_CYCLE = """; a user cycle
G01 X[@P1] Y[@P2] F[@P3]
V.CYC.Done = @P1 * @P2
M17
"""


def test_user_cycle_file_reads_its_parameters_and_writes_outputs() -> None:
    text = """#VAR
  V.CYC.Done = 0
#ENDVAR
G00 X1 Y1
L CYCLE [NAME=mill.ecy @P1 = 3 @P2 = 4 @P3 = 600]
G01 X[V.CYC.Done] Y0
M30
"""
    channel = Channel({"mill.ecy": USER_CYCLE})
    _, blocks = channel.run(text)
    moves = motion_blocks(blocks)
    assert [(b.source.file, b.source.line) for b in moves] == \
        [("prog.nc", 4), ("mill.ecy", 2), ("prog.nc", 6)]
    assert moves[1].motion.kind == MotionKind.LINEAR
    assert moves[1].motion.start_mm == (1.0, 1.0, 0.0)
    assert moves[1].motion.end_mm == (3.0, 4.0, 0.0)
    assert moves[1].motion.feed_mm_s == pytest.approx(10.0)
    assert moves[2].motion.end_mm == (12.0, 0.0, 0.0)  # V.CYC.Done = 12 in the caller
    assert moves[2].motion.feed_mm_s == pytest.approx(10.0)  # F is not restored


def test_output_declared_in_a_calling_subprogram() -> None:
    files = {"sub.nc": ("#VAR\nV.CYC.SysRetRadius\n#ENDVAR\n"
                        "L CYCLE [NAME=SysCalcCircle.ecy @P50=0 @P60=-3 @P51=0 @P61=3 @P52=3 @P62=0]\n"
                        '#FILE NAME [MSG="r.txt"]\n#MSG SAVE ["r=%g", V.CYC.SysRetRadius]\nM17\n')}
    channel = Channel(files)
    channel.run("L sub.nc\nM30\n")
    assert channel.files["r.txt"] == "r=3\n"


def test_user_cycle_reading_a_parameter_not_given() -> None:
    channel = Channel({"mill.ecy": USER_CYCLE})
    error = channel.error("L CYCLE [NAME=mill.ecy @P1=3 @P3=100]\nM30\n")
    assert_at(error, E.CYCLE_PARAMETER_UNDEFINED, USER_CYCLE, "@P2", file="mill.ecy")
    assert "@P2" in error.message


def test_parameter_outside_a_cycle() -> None:
    text = "G01 F100\nX[@P7 + 1]\nM30\n"
    error = Channel().error(text)
    assert_at(error, E.CYCLE_PARAMETER_UNDEFINED, text, "@P7")
    assert "@P7" in error.message


def test_parameters_belong_to_their_call() -> None:
    # after the cycle returns, its @P are gone
    text = "L CYCLE [NAME=c.ecy @P1=5]\nG01 F100 X[@P1]\nM30\n"
    channel = Channel({"c.ecy": "G01 X[@P1] F100\nM17\n"})
    error = channel.error(text)
    assert_at(error, E.CYCLE_PARAMETER_UNDEFINED, text, "@P1", occurrence=1)


def test_nested_user_cycles_see_their_own_parameters() -> None:
    files = {"outer.ecy": "G01 X[@P1] F100\nL CYCLE [NAME=inner.ecy @P1 = @P1 + 10]\nY[@P1]\nM17\n",
             "inner.ecy": "G01 X[@P1]\nM17\n"}
    _, blocks = Channel(files).run("L CYCLE [NAME=outer.ecy @P1=2]\nM30\n")
    assert [b.motion.end_mm for b in motion_blocks(blocks)] == \
        [(2.0, 0.0, 0.0), (12.0, 0.0, 0.0), (12.0, 2.0, 0.0)]


def test_user_cycle_missing_in_the_store() -> None:
    text = "L CYCLE [NAME=mill.ecy @P1=1]\nM30\n"
    assert_at(Channel().error(text), E.CYCLE_NOT_FOUND, text, "mill.ecy")


def test_local_cycle_runs_a_percent_l_section() -> None:
    text = """G01 F100 X1
LL CYCLE [NAME=SUB @P1 = 2 @P2 = 5]
X9
M30
%L SUB
G00 X[@P1 * 10] Y[@P2]
M17
"""
    _, blocks = Channel().run(text)
    moves = motion_blocks(blocks)
    assert [(b.source.line, b.motion.kind, b.motion.end_mm) for b in moves] == [
        (1, MotionKind.LINEAR, (1.0, 0.0, 0.0)),
        (6, MotionKind.RAPID, (20.0, 5.0, 0.0)),
        (3, MotionKind.LINEAR, (9.0, 5.0, 0.0)),  # the caller's G01 again
    ]


def test_local_cycle_without_its_section() -> None:
    text = "LL CYCLE [NAME=SUB @P1=2]\nM30\n%L OTHER\nM17\n"
    assert_at(Channel().error(text), E.CYCLE_NOT_FOUND, text, "SUB")


def test_callers_modal_functions_are_restored_after_a_cycle() -> None:
    files = {"modal.ecy": "G91 G00 X1\nG18\nM17\n"}
    text = "G90 G01 F100 X5\nL CYCLE [NAME=modal.ecy]\nX7\nG02 X9 Y2 I1 J1\nM30\n"
    d, blocks = Channel(files).run(text)
    moves = motion_blocks(blocks)
    assert [(b.source.file, b.motion.kind, b.motion.end_mm) for b in moves] == [
        ("prog.nc", MotionKind.LINEAR, (5.0, 0.0, 0.0)),
        ("modal.ecy", MotionKind.RAPID, (6.0, 0.0, 0.0)),  # G91 inside the cycle
        ("prog.nc", MotionKind.LINEAR, (7.0, 0.0, 0.0)),  # G90 G01 again
        ("prog.nc", MotionKind.ARC_CW, (9.0, 2.0, 0.0)),  # G17 again: X/Y arc
    ]
    assert moves[3].motion.plane == (0, 1)
    assert d.modal.plane == Plane.XY and d.modal.distance == DistanceMode.ABSOLUTE


def test_incremental_rapid_caller_is_restored_too() -> None:
    files = {"modal.ecy": "G90 G01 X50 F100\nM17\n"}
    text = "G91 G00 X1\nL CYCLE [NAME=modal.ecy]\nX1\nM30\n"
    d, blocks = Channel(files).run(text)
    last = motion_blocks(blocks)[-1]
    assert (last.motion.kind, last.motion.start_mm, last.motion.end_mm) == \
        (MotionKind.RAPID, (50.0, 0.0, 0.0), (51.0, 0.0, 0.0))
    assert d.modal.distance == DistanceMode.INCREMENTAL


# ---------------------------------------------------------------- 6. SysHscSettings

DESELECT_PROGRAM = ("% manufacturerHscDeselectSettings.nc\nG133 = 100\nG134 = 100\n#HSC OFF\n"
                    "#FILTER OFF\nM17\n")
FINISH_PROGRAM = """% manufacturerHscFinishSettings.nc
G133 = 80
G134 = 70
#SLOPE[TYPE=HSC]
#HSC ON[SURFACE PATH_DEV=V.G.HSCS.FINISH.TOLERANCE \\
          TRACK_DEV=V.G.HSCS.FINISH.TOLERANCE]
#FILTER ON [AX_DEV=V.G.HSCS.FINISH.TOLERANCE * 2]
M17
"""
HSC_EXAMPLE = """; HSC Settings
T9 D9 ( Tool data )
M6                                ( Tool change )
G00 G17 G90 F2000 M03 S6000      ( Technology data )
G00 Z150                          ( Go to z start position )
G00 X0 Y0                          ( position over the workpiece )

; Finishing Mode
L CYCLE [NAME=SysHscSettings.ecy  \\
      @P1 = 4                      \\
      ]

; 3D Milling
;...
;...

M30
"""
MODES = ("DESELECT", "ROUGH", "PREFINISH", "FINISH")


def hsc_channel() -> Channel:
    files = {"manufacturerHscDeselectSettings.nc": DESELECT_PROGRAM,
             "manufacturerHscFinishSettings.nc": FINISH_PROGRAM}
    hscs = {"DESELECT": HscProgram("manufacturerHscDeselectSettings.nc", 0.1),
            "ROUGH": HscProgram("rough.nc", 0.05),
            "PREFINISH": HscProgram("prefinish.nc", 0.02),
            "FINISH": HscProgram("manufacturerHscFinishSettings.nc", 0.01)}
    return Channel(files, hscs=hscs)


def test_hsc_example_switches_the_finish_settings() -> None:
    d, blocks = hsc_channel().run(HSC_EXAMPLE)
    s = d.modal.settings
    assert (s.hsc, s.hsc_surface) == (True, True)
    assert s.hsc_path_dev_mm == pytest.approx(0.01, abs=1e-15)
    assert s.hsc_track_dev_mm == pytest.approx(0.01, abs=1e-15)
    assert (s.acc_weight_pct, s.ramp_weight_pct) == (80.0, 70.0)
    assert s.slope == "HSC"
    assert s.filter is True and s.filter_ax_dev_mm == pytest.approx(0.02, abs=1e-15)
    assert blocks[-1].source.line == 17  # M30 of the example
    moves = motion_blocks(blocks)
    assert moves[-1].motion.end_mm == (0.0, 0.0, 150.0)  # the cycle moves nothing


def test_hsc_deselect_program_of_the_documentation() -> None:
    channel = hsc_channel()
    text = ("L CYCLE [NAME=SysHscSettings.ecy @P1=4]\nL CYCLE [NAME=SysHscSettings.ecy @P1 = 1]\n"
            "M30\n")
    d, _ = channel.run(text)
    s = d.modal.settings
    assert (s.hsc, s.filter, s.acc_weight_pct, s.ramp_weight_pct) == (False, False, 100.0, 100.0)
    assert s.slope == "HSC"  # the deselect program leaves #SLOPE as it is


def test_hsc_mode_defaults_to_deselect() -> None:
    d, _ = hsc_channel().run("L CYCLE [NAME=SysHscSettings.ecy @P1=4]\n"
                             "L CYCLE [NAME=SysHscSettings.ecy]\nM30\n")
    assert d.modal.settings.hsc is False and d.modal.settings.acc_weight_pct == 100.0


@pytest.mark.parametrize("mode", [1, 2, 3, 4])
def test_each_hsc_mode_calls_its_own_program(mode) -> None:
    tolerances = {"DESELECT": 0.125, "ROUGH": 0.0625, "PREFINISH": 0.03125, "FINISH": 0.015625}
    files = {f"{m.lower()}.nc": f'#MSG SAVE ["{m} %g", V.G.HSCS.{m}.TOLERANCE]\nG01 X{k + 1}\nM17\n'
             for k, m in enumerate(MODES)}
    hscs = {m: HscProgram(f"{m.lower()}.nc", tolerances[m]) for m in MODES}
    channel = Channel(files, hscs=hscs)
    _, blocks = channel.run(f"G01 F100\nL CYCLE [NAME=SysHscSettings.ecy @P1={mode}]\nM30\n")
    name = MODES[mode - 1]
    assert channel.files["msg_save.txt"] == f"{name} {tolerances[name]:g}\n"
    (move,) = motion_blocks(blocks)
    assert move.source.file == f"{name.lower()}.nc"
    assert move.motion.end_mm == (float(mode), 0.0, 0.0)


def test_hsc_tolerances_are_readable_anywhere() -> None:
    channel = hsc_channel()
    channel.run('#MSG ["%g %g %g %g", V.G.HSCS.DESELECT.TOLERANCE, V.G.HSCS.ROUGH.TOLERANCE, '
                'V.G.HSCS.PREFINISH.TOLERANCE, V.G.HSCS.FINISH.TOLERANCE]\nM30\n')
    assert channel.messages == ["0.1 0.05 0.02 0.01"]


@pytest.mark.parametrize("value", ["5", "0", "2.5", '"FINISH"'])
def test_hsc_mode_out_of_range(value) -> None:
    text = f"L CYCLE [NAME=SysHscSettings.ecy @P1={value}]\nM30\n"
    assert_at(hsc_channel().error(text), E.CYCLE_PARAMETER_RANGE, text, "@P1")


def test_hsc_unknown_parameter() -> None:
    text = "L CYCLE [NAME=SysHscSettings.ecy @P1=4 @P2=1]\nM30\n"
    assert_at(hsc_channel().error(text), E.CYCLE_PARAMETER_UNKNOWN, text, "@P2")


def test_hsc_mode_without_a_program() -> None:
    channel = hsc_channel()
    channel.hscs["ROUGH"] = HscProgram("", 0.05)
    text = "L CYCLE [NAME=SysHscSettings.ecy @P1=2]\nM30\n"
    error = channel.error(text)
    assert_at(error, E.CYCLE_NOT_FOUND, text, "@P1")
    assert "rough" in error.message.lower()
    del channel.hscs["ROUGH"]  # no entry at all
    assert channel.error(text).id == E.CYCLE_NOT_FOUND


def test_hsc_program_missing_in_the_store() -> None:
    text = "L CYCLE [NAME=SysHscSettings.ecy @P1=3]\nM30\n"
    error = hsc_channel().error(text)  # prefinish.nc is not in the store
    assert_at(error, E.CYCLE_NOT_FOUND, text, "@P1")
    assert "prefinish.nc" in error.message


def test_hsc_program_is_read_as_a_subprogram() -> None:
    channel = hsc_channel()
    channel.files["rough.nc"] = "G133 = 180\n"  # no M17
    error = channel.error("L CYCLE [NAME=SysHscSettings.ecy @P1=2]\nM30\n")
    assert (error.id, error.file) == (E.SUBPROGRAM_END_MISSING, "rough.nc")


# ---------------------------------------------------------------- 7. syntax check

def check(text: str, channel: Channel) -> Run:
    recorder = Recorder()
    d = channel.decoder(text, check=recorder)
    items = list(islice(d.blocks(), 10_000))
    assert len(items) < 10_000
    return Run(recorder, items, d)


CHECKED = """G01 F100 X1
#FILE NAME [MSG="out.txt"]
#MSG SAVE EXCLUSIVE ["a %d", 1]
L CYCLE [NAME=SysCalcCircle.ecy \\
  @P50=0 @P60=0 @P51=1 @P61=1 @P52=2 @P62=5 \\
  @P70=3 \\
  @P53="x" @P63=4 \\
]
#MSG ["shown %d", 2]
L CYCLE [NAME=SysPosRotationToPlane.ecy @P1=3 @P20=1 @P15=10]
X2
L CYCLE [NAME=SysCalcCircle.ecy @P50=0 @P60=0 @P51=1 @P61=1 @P52=2 @P62=2]
X3
M30
"""


def test_check_reports_every_bad_parameter_of_a_call_and_goes_on() -> None:
    channel = Channel({"out.txt": "keep\n"})
    run = check(CHECKED, channel)
    found = [(e.id, e.file, e.line, e.column) for e, _ in run.check.errors]
    assert found == [
        (E.CYCLE_PARAMETER_RANGE, "prog.nc", *where(CHECKED, "@P53")),
        (E.CYCLE_PARAMETER_UNKNOWN, "prog.nc", *where(CHECKED, "@P70")),
        (E.CYCLE_POINTS_COLLINEAR, "prog.nc", *where(CHECKED, "SysCalcCircle.ecy", 1)),
    ]
    assert all("@P53" in e.message for e, _ in run.check.errors[:1])
    assert "@P70" in run.check.errors[1][0].message
    assert all(isinstance(cat, ErrorCategory) for _, cat in run.check.errors)
    assert channel.files == {"out.txt": "keep\n"}  # nothing written, no result file
    assert channel.writes == [] and channel.messages == []
    assert run.ends() == [(1.0, 0.0, 0.0), (2.0, 0.0, 0.0), (3.0, 0.0, 0.0)]
    assert run.ended()


def test_check_reports_missing_points_with_unknown_parameters() -> None:
    text = "L CYCLE [NAME=SysCalcCircle.ecy @P50=0 @P60=0 @P51=1 @P70=1]\nG01 F100 X4\nM30\n"
    run = check(text, Channel())
    errors = [e for e, _ in run.check.errors]
    assert [e.id for e in errors] == [E.CYCLE_PARAMETER_UNKNOWN] + [E.CYCLE_PARAMETER_MISSING] * 3
    assert "@P70" in errors[0].message
    assert ["@P61" in errors[1].message, "@P52" in errors[2].message,
            "@P62" in errors[3].message] == [True, True, True]
    assert run.ends() == [(4.0, 0.0, 0.0)] and run.ended()


def test_check_of_user_cycles_and_unknown_cycles() -> None:
    channel = Channel({"c.ecy": "G01 X[@P1] F100\nM17\n"})
    text = "L CYCLE [NAME=Nope.ecy]\nL CYCLE [NAME=c.ecy @P2=4]\nL CYCLE [NAME=c.ecy @P1=4]\nM30\n"
    run = check(text, channel)
    assert [(e.id, e.file, e.line) for e, _ in run.check.errors] == [
        (E.CYCLE_NOT_FOUND, "prog.nc", 1), (E.CYCLE_PARAMETER_UNDEFINED, "c.ecy", 1)]
    assert run.ends()[-1] == (4.0, 0.0, 0.0) and run.ended()


def test_check_without_errors_runs_the_cycle() -> None:
    channel = Channel()
    text = ("#VAR\nV.CYC.SysRetRadius\n#ENDVAR\n"
            "L CYCLE [NAME=SysCalcCircle.ecy @P50=0 @P60=-2 @P51=0 @P61=2 @P52=2 @P62=0]\n"
            "G01 F100 X[V.CYC.SysRetRadius]\nM30\n")
    run = check(text, channel)
    assert run.check.errors == []
    assert run.ends() == [pytest.approx((2.0, 0.0, 0.0), abs=1e-12)]
