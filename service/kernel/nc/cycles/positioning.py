"""SysPosRotationToPlane: rotate the machining coordinate system onto a plane (§3.2).

The plane comes from three reference points @P6..@P14 (``rotation.rotation_from_points``:
X along point 1 -> point 2, Z normal with positive Z, Y = Z x X) or from the angles
@P15 (A, about X), @P16 (B, about Y), @P17 (C, about Z) in the order @P19 (1 XYZ ..
6 ZYX, default) intrinsic (@P18 = 1, default) or extrinsic (@P18 = 2). Positions and
angles refer to the coordinate system active before the call.

Process: with @P2 > 0 the tool first retracts by @P2 along its axis (machine +Z; this
kernel has no kinematic transformation, so the tool is always along machine Z). Then,
by @P1:

* 1: machining coordinate system and tool are rotated (needs a kinematic
  transformation: an error here, none is configured);
* 2: only the tool is rotated (same);
* 3: only the machining coordinate system: after the cycle a ``#CS`` with its origin
  at @P3..@P5 and the rotated axes is active, ``#CS OFF`` deselects it;
* 4: nothing moves or changes; only the result (with @P20 = 1).

@P20 = 1 writes ``SysPosRotationToPlaneResult.txt`` (replaced on every call)::

    SysPosRotationToPlane result
    Mode = 3
    Origin = 140.000000, 0.000000, -80.000000
    X axis = 0.000000, 1.000000, 0.000000
    Y axis = -0.514496, 0.000000, 0.857493
    Z axis = 0.857493, 0.000000, 0.514496
    #CS ON [140.000000, 0.000000, -80.000000, A, B, C]

The axes are the unit vectors of the new coordinate system in the coordinate system
before the call; the last line is the ``#CS`` with ISG's standard angles (Z, Y', X'')
that selects the same system.
"""

from __future__ import annotations

from collections.abc import Mapping

from ...path.kinematics import KinematicsError
from ..errors import NcErrorId
from ..literals import nc_number
from ..tool_orientation import normal_of, rotary_of, turn_line
from ..variables import Value
from .rotation import (
    Matrix,
    RotationError,
    RotationOrder,
    Vector,
    angles_from_rotation,
    rotation_from_angles,
    rotation_from_points,
)
from .spec import BuiltinCycle, CycleContext, ParamProblem, ParamSpec

RESULT_FILE = "SysPosRotationToPlaneResult.txt"
_POINTS = tuple(range(6, 15))
_ANGLES = (15, 16, 17)
_COORD = ("X", "Y", "Z")

PARAMS = {
    1: ParamSpec("rotation mode", 1, 1, 4, True),
    2: ParamSpec("retraction distance", 0, 0),
    3: ParamSpec("X of the new origin", 0),
    4: ParamSpec("Y of the new origin", 0),
    5: ParamSpec("Z of the new origin", 0),
    **{6 + k: ParamSpec(f"{_COORD[k % 3]} of reference point {k // 3 + 1}") for k in range(9)},
    15: ParamSpec("rotation about X (A) in degrees"),
    16: ParamSpec("rotation about Y (B) in degrees"),
    17: ParamSpec("rotation about Z (C) in degrees"),
    18: ParamSpec("rotation mode 1 intrinsic / 2 extrinsic", 1, 1, 2, True),
    19: ParamSpec("rotation order 1 XYZ .. 6 ZYX", 6, 1, 6, True),
    20: ParamSpec("result output 0 / 1", 0, 0, 1, True),
}


def _check(values: Mapping[int, Value]) -> list[ParamProblem]:
    points = [n for n in _POINTS if n in values]
    angles = [n for n in _ANGLES if n in values]
    if points and angles:
        return [ParamProblem(NcErrorId.CYCLE_PARAMETER_UNKNOWN, angles[0],
                             f"@P{angles[0]}: the plane is given by reference points "
                             "(@P6..@P14) or by angles (@P15..@P17), not both")]
    if not points and not angles:
        return [ParamProblem(NcErrorId.CYCLE_PARAMETER_MISSING, None,
                             "SysPosRotationToPlane.ecy needs the plane: reference points "
                             "@P6..@P14 or angles @P15..@P17")]
    return [ParamProblem(NcErrorId.CYCLE_PARAMETER_MISSING, None,
                         f"@P{n} ({PARAMS[n].meaning}) is missing: the three reference "
                         "points need all of @P6..@P14")
            for n in _POINTS if points and n not in values]


def _point(params: Mapping[int, Value], first: int) -> Vector:
    """The reference point in @P<first>..@P<first + 2> (numbers: check_parameters)."""
    x, y, z = (float(params[n]) for n in (first, first + 1, first + 2))
    return (x, y, z)


def _rotation(context: CycleContext) -> Matrix:
    p = context.params
    if 6 in context.given:
        try:
            return rotation_from_points(_point(p, 6), _point(p, 9), _point(p, 12))
        except RotationError as fault:
            err_id = (NcErrorId.CYCLE_POINTS_IDENTICAL if "coincide" in fault.message
                      else NcErrorId.CYCLE_POINTS_COLLINEAR)
            raise context.error(err_id, f"SysPosRotationToPlane.ecy: {fault.message}", 6) \
                from None
    a, b, c = (float(p.get(n, 0.0)) for n in _ANGLES)
    return rotation_from_angles(a, b, c, RotationOrder(int(p[19])), int(p[18]) == 1)


def _run(context: CycleContext) -> str | None:
    p = context.params
    mode = int(p[1])
    chain = context.decoder.surroundings.kinematic_chain
    if mode in (1, 2) and (chain is None or not context.modal.settings.trafo):
        why = ("none is configured for this channel" if chain is None else
               "program #TRAFO ON before the call")
        raise context.error(
            NcErrorId.TRAFO_NOT_CONFIGURED,
            f"SysPosRotationToPlane.ecy @P1={mode} rotates the tool, which needs the "
            f"kinematic transformation active; {why} (use @P1=3 to rotate only the "
            "machining coordinate system)", 1)
    rotation = _rotation(context)
    origin = tuple(float(p[n]) for n in (3, 4, 5))
    a, b, c = angles_from_rotation(rotation, RotationOrder.ZYX, True)
    cs_line = f"#CS ON [{', '.join(nc_number(v) for v in (*origin, a, b, c))}]"
    if int(p[20]) == 1:
        columns = [tuple(row[k] for row in rotation) for k in range(3)]
        lines = ["SysPosRotationToPlane result", f"Mode = {mode}",
                 "Origin = " + ", ".join(f"{v:f}" for v in origin)]
        lines += [f"{axis} axis = " + ", ".join(f"{v + 0.0:f}" for v in column)
                  for axis, column in zip(_COORD, columns, strict=True)]
        lines.append("#CS ON [" + ", ".join(f"{v + 0.0:f}" for v in (*origin, a, b, c)) + "]")
        context.write_file(RESULT_FILE, "\n".join(lines) + "\n")
    if mode == 4:
        return None
    body = []
    retract = float(p[2])
    if retract > 0.0:
        body.append(_retraction(context, retract))
    if mode in (1, 2):  # the tool turns onto the plane's normal, its tip stays (RTCP)
        body.append(_tool_onto(context, rotation))
    if mode in (1, 3):  # @P1=2 rotates only the tool: the MCS stays as it is
        body.append(cs_line)
    body.append("M17")
    return "\n".join(body) + "\n"


def _tool_direction(context: CycleContext) -> Vector:
    """The tool's direction in the decoder's coordinates: machine +Z without a
    transformation, else what the rotary axes turn it to."""
    chain = context.decoder.surroundings.kinematic_chain
    if chain is None or not context.modal.settings.trafo:
        return (0.0, 0.0, 1.0)
    return chain.forward(dict(enumerate(context.modal.position_mm))).orientation


def _retraction(context: CycleContext, distance_mm: float) -> str:
    """G0 by ``distance_mm`` along the tool (machine +Z without a transformation),
    written in the active coordinates."""
    decoder = context.decoder
    ix, iy, iz = decoder.executor.xyz
    position = context.modal.position_mm
    dx, dy, dz = _tool_direction(context)
    target = (position[ix] + distance_mm * dx, position[iy] + distance_mm * dy,
              position[iz] + distance_mm * dz)
    placement = context.modal.cs_placement
    if placement is not None:
        target = placement.from_machine(target)
    x, y, z = (nc_number(v) for v in target)
    return f"G90 G00 X{x} Y{y} Z{z}"


def _tool_onto(context: CycleContext, rotation: Matrix) -> str:
    """G0 of the rotary axes that turns the tool onto the Z axis of ``rotation`` (in the
    coordinates before the call), the solution nearer the rotary axes' positions; the
    tip stays where it is (``#TRAFO ON``)."""
    chain = context.decoder.surroundings.kinematic_chain
    assert chain is not None  # _run checked
    try:
        line, _ = turn_line(chain, context.decoder.axes, normal_of(rotation, context.modal),
                            rotary_of(chain, context.modal))
    except KinematicsError as fault:
        raise context.error(NcErrorId.TRAFO_POSE_UNREACHABLE,
                            f"SysPosRotationToPlane.ecy: {fault}", 1) from None
    return line


ROTATION_TO_PLANE = BuiltinCycle("SysPosRotationToPlane.ecy", PARAMS, _run, _check)
