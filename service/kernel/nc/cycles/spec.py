"""Parameters of a built-in cycle: what each @P means, its default and its range.

A built-in cycle declares its parameters (``ParamSpec``); a call is checked against
them before the cycle runs (``check_parameters``): an @P the cycle does not have, a
required one that is missing, a string where a number belongs, a value outside its
range or not an integer where one is needed: each is an error naming the parameter.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Protocol

from ..errors import NcError, NcErrorId
from ..modal import ModalState
from ..running_decoder import CallingDecoder
from ..variables import Value


class CycleContext(Protocol):
    """What a built-in cycle sees when it runs (``cycle_run.CycleContext``)."""

    decoder: CallingDecoder  # the decoder running the call
    modal: ModalState  # its modal state
    params: dict[int, Value]  # the call's parameters, defaults filled in
    given: dict[int, Value]  # the parameters the call gave

    def error(self, err_id: NcErrorId, message: str, param: int | None = None) -> NcError:
        """An error at the parameter's ``@P`` in the call (else at its NAME)."""

    def set_output(self, name: str, value: Value) -> None:
        """``V.CYC.<name>`` of the caller, when it declared one."""

    def write_file(self, name: str, text: str) -> None:
        """Replace file ``name`` of the store (nothing in a syntax check)."""


@dataclass(frozen=True, slots=True)
class ParamSpec:
    """One @P parameter of a built-in cycle."""

    meaning: str
    default: float | None = None  # None: no default (required, or optional without one)
    low: float = -math.inf
    high: float = math.inf
    integer: bool = False


@dataclass(frozen=True, slots=True)
class ParamProblem:
    """A parameter error: its id, the parameter (None: the call as a whole), the text."""

    err_id: NcErrorId
    number: int | None
    message: str


@dataclass(frozen=True, slots=True)
class BuiltinCycle:
    """A cycle implemented in Python behind the ``L CYCLE`` call.

    ``check(values)`` finds the problems between parameters (which are required depends
    on which others are given); ``run(context)`` executes the cycle and returns the NC
    text of its motion part (run as the cycle's body, ending with M17) or None.
    """

    name: str
    params: Mapping[int, ParamSpec]
    run: Callable[[CycleContext], str | None]
    check: Callable[[Mapping[int, Value]], list[ParamProblem]] = lambda values: []


def check_parameters(cycle: BuiltinCycle, values: Mapping[int, Value]) -> list[ParamProblem]:
    """Every problem of ``values`` against the cycle's parameters: those of single
    parameters in @P order, then those between parameters."""
    problems: list[ParamProblem] = []
    for number in sorted(values):
        spec = cycle.params.get(number)
        value = values[number]
        if spec is None:
            problems.append(ParamProblem(NcErrorId.CYCLE_PARAMETER_UNKNOWN, number,
                                         f"@P{number} is not a parameter of {cycle.name}"))
        elif isinstance(value, str):
            problems.append(ParamProblem(NcErrorId.CYCLE_PARAMETER_RANGE, number,
                                         f"@P{number} ({spec.meaning}) of {cycle.name} must be "
                                         f"a number, not the string \"{value}\""))
        elif not math.isfinite(value) or not spec.low <= value <= spec.high or (
                spec.integer and value != int(value)):
            problems.append(ParamProblem(NcErrorId.CYCLE_PARAMETER_RANGE, number,
                                         f"@P{number} ({spec.meaning}) of {cycle.name} = "
                                         f"{value:g} is outside {_range(spec)}"))
    # the problems between parameters too (a syntax check reports all of them); they
    # depend on which parameters are given, so the ones the cycle does not have are left out
    problems += cycle.check({n: v for n, v in values.items() if n in cycle.params})
    return problems


def _range(spec: ParamSpec) -> str:
    kind = "integers " if spec.integer else ""
    if spec.low == -math.inf and spec.high == math.inf:
        return "the finite numbers"
    if spec.high == math.inf:
        return f"{kind}>= {spec.low:g}"
    if spec.low == -math.inf:
        return f"{kind}<= {spec.high:g}"
    return f"{kind}{spec.low:g}..{spec.high:g}"


def with_defaults(cycle: BuiltinCycle, values: Mapping[int, Value]) -> dict[int, Value]:
    """``values`` completed with the defaults of the parameters not given."""
    done: dict[int, Value] = {
        n: spec.default for n, spec in cycle.params.items() if spec.default is not None
    }
    done.update(values)
    return done
