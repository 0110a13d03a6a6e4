"""The built-in cycles, by upper-case name (``L CYCLE [NAME=SysCalcCircle.ecy ..]``)."""

from __future__ import annotations

from collections.abc import Mapping

from ..variables import Value
from .calculation import CALCULATION_CYCLES
from .hsc import HSC_SETTINGS
from .positioning import ROTATION_TO_PLANE
from .spec import BuiltinCycle, ParamProblem, check_parameters, with_defaults

BUILTIN_CYCLES: dict[str, BuiltinCycle] = {
    cycle.name.upper(): cycle
    for cycle in (*CALCULATION_CYCLES, ROTATION_TO_PLANE, HSC_SETTINGS)
}


def builtin_problems(
    cycle: BuiltinCycle, values: Mapping[int, Value]
) -> tuple[list[ParamProblem], dict[int, Value]]:
    """The problems of a call's parameters and the parameters with defaults filled in."""
    return check_parameters(cycle, values), with_defaults(cycle, values)
