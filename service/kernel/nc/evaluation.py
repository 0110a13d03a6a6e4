"""Evaluating parsed expressions: nodes, operators, functions, value checks.

A parsed expression is a callable ``node(env)``; ``env`` finds variables
(``env.find_variable(scope, name)``, the running Decoder). Constants are ``Const``
nodes, variables ``VarRef`` nodes (also assignable). Operator chains of one precedence
level are one closure folding over its operands (``fold``), so ``1+1+...+1`` does not
nest Python calls. An operator that fails raises a ``Fault`` (no place); the closure
turns it into an NcError at the operator's position.

Numbers are floats; ``**`` uses ``math.pow`` so that a huge power is an error, not a
giant integer. Functions take degrees (SIN, COS, TAN) and give degrees (ASIN, ACOS,
ATAN, ATAN2); INT truncates toward zero, ROUND rounds halves away from zero, FRACT is
x - INT[x]. AND and OR evaluate their right side only when needed.
"""

from __future__ import annotations

import math
import operator
from collections.abc import Callable, Sequence
from typing import Any, Protocol

from .errors import NcErrorId
from .source import LogicalLine
from .variables import Scope, Value, Variable, VariableFault, round_half_away

Node = Callable[[Any], Value]
Fault = VariableFault


class Env(Protocol):
    """What evaluation needs from the interpreter."""

    def find_variable(self, scope: Scope, name: str) -> Variable | None:
        """The visible variable ``V.<scope>.<name>`` or None."""

    def cycle_parameter(self, number: int, line: LogicalLine, pos: int) -> Value:
        """``@P<number>`` of the innermost running cycle (NcError at ``pos`` if none)."""

    def write_zero_offset(self, variable: Variable, indices: tuple[int, ...], value: Value,
                          line: LogicalLine, pos: int) -> None:
        """``V.G.NP[j].V... = value``: write a zero offset (``nc.zero_offset_writes``)."""


class Const:
    """A node whose value is known when parsed."""

    __slots__ = ("value",)

    def __init__(self, value: Value) -> None:
        self.value = value

    def __call__(self, env: Any) -> Value:
        return self.value


class VarRef:
    """``V.<scope>.<name>[i][j]``: readable as a node, assignable."""

    __slots__ = ("scope", "name", "full", "indices", "line", "pos")

    def __init__(
        self, scope: Scope, name: str, indices: tuple[Node, ...], line: LogicalLine, pos: int
    ) -> None:
        self.scope = scope
        self.name = name
        self.full = f"V.{scope.name}.{name}"
        self.indices = indices
        self.line = line
        self.pos = pos

    def _resolve(self, env: Env) -> tuple[Variable, tuple[int, ...]]:
        var = env.find_variable(self.scope, self.name)
        if var is None:
            raise self.line.error(
                NcErrorId.UNDECLARED_VARIABLE, f"undeclared variable {self.full}", self.pos
            )
        if not self.indices:
            return var, ()
        return var, tuple(_index(node(env), self.line, self.pos) for node in self.indices)

    def __call__(self, env: Env) -> Value:
        var, indices = self._resolve(env)
        try:
            return var.get(indices)
        except Fault as f:
            raise self.line.error(f.err_id, f.message, self.pos) from None

    def assign(self, env: Env, value: Value) -> None:
        """Store ``value`` (converted to the variable's type)."""
        var, indices = self._resolve(env)
        if self.scope == Scope.G and self.name.startswith("NP.V"):
            env.write_zero_offset(var, indices, value, self.line, self.pos)
            return
        try:
            var.set(value, indices)
        except Fault as f:
            raise self.line.error(f.err_id, f.message, self.pos) from None


class ParamRef:
    """``@P<n>`` inside a cycle: the value its call passed (read only)."""

    __slots__ = ("number", "line", "pos")

    def __init__(self, number: int, line: LogicalLine, pos: int) -> None:
        self.number = number
        self.line = line
        self.pos = pos

    def __call__(self, env: Env) -> Value:
        return env.cycle_parameter(self.number, self.line, self.pos)


def _index(value: Value, line: LogicalLine, pos: int) -> int:
    if isinstance(value, str) or not math.isfinite(value) or value != int(value):
        raise line.error(
            NcErrorId.ARRAY_INDEX_MISMATCH, f"array index {value!r} is not an integer", pos
        )
    return int(value)


def number(value: Value, line: LogicalLine, pos: int, what: str = "a number") -> float:
    """``value`` as a float; TYPE_MISMATCH at ``pos`` for a string."""
    if isinstance(value, str):
        raise line.error(NcErrorId.TYPE_MISMATCH, f"expected {what}, got the string {value!r}", pos)
    return float(value)


def truth(value: Value, line: LogicalLine, pos: int) -> bool:
    """Truth of a condition: non-zero numbers and TRUE."""
    if isinstance(value, str):
        raise line.error(NcErrorId.TYPE_MISMATCH, f"condition is the string {value!r}", pos)
    return value != 0


# ------------------------------------------------------------------ operators


def _numbers(a: Value, b: Value, op: str) -> tuple[float, float]:
    """``a`` and ``b`` unchanged (int, bool or float); a Fault when one is a string."""
    if isinstance(a, str) or isinstance(b, str):
        raise Fault(NcErrorId.TYPE_MISMATCH, f"operator {op} needs numbers")
    return a, b


def _add(a: Value, b: Value) -> Value:
    if isinstance(a, str) and isinstance(b, str):
        return a + b
    x, y = _numbers(a, b, "+")
    return x + y


def _arith(op: str, fn: Callable[[Any, Any], Value]) -> Callable[[Value, Value], Value]:
    def apply(a: Value, b: Value) -> Value:
        return fn(*_numbers(a, b, op))

    return apply


def _div(a: Value, b: Value) -> Value:
    x, y = _numbers(a, b, "/")
    if y == 0:
        raise Fault(NcErrorId.DIVISION_BY_ZERO, "division by zero")
    return x / y


def _mod(a: Value, b: Value) -> Value:
    a, b = _numbers(a, b, "MOD")
    if b == 0:
        raise Fault(NcErrorId.DIVISION_BY_ZERO, "division by zero (MOD 0)")
    try:
        return math.fmod(a, b)
    except ValueError:  # an infinite dividend
        raise Fault(NcErrorId.MATH_DOMAIN, f"{a:g} MOD {b:g} is not defined") from None


def pow_op(a: Value, b: Value) -> Value:
    """a ** b (and a ^ b) as a float; Fault when undefined or too large."""
    a, b = _numbers(a, b, "**")
    try:
        return math.pow(a, b)
    except (ValueError, OverflowError):
        raise Fault(NcErrorId.MATH_DOMAIN, f"{a:g} ** {b:g} is not defined or too large") from None


def _compare(op: str, fn: Callable[[Any, Any], bool]) -> Callable[[Value, Value], Value]:
    def apply(a: Value, b: Value) -> Value:
        if isinstance(a, str) != isinstance(b, str):
            raise Fault(NcErrorId.TYPE_MISMATCH, f"cannot compare a string with a number ({op})")
        if isinstance(a, str) and op not in ("==", "!=", "<>"):
            raise Fault(NcErrorId.TYPE_MISMATCH, "strings can only be compared with == and !=")
        return fn(a, b)

    return apply


ADD_OPS = {"+": _add, "-": _arith("-", operator.sub)}
MUL_OPS = {"*": _arith("*", operator.mul), "/": _div, "MOD": _mod}
CMP_OPS = {
    "==": _compare("==", operator.eq), "!=": _compare("!=", operator.ne),
    "<>": _compare("<>", operator.ne), "<=": _compare("<=", operator.le),
    ">=": _compare(">=", operator.ge), "<": _compare("<", operator.lt),
    ">": _compare(">", operator.gt),
}
CMP_SYMBOLS = ("==", "!=", "<>", "<=", ">=", "<", ">")


def _deg(fn: Callable[[float], float]) -> Callable[[float], float]:
    return lambda x: fn(math.radians(x))


def _to_deg(fn: Callable[[float], float]) -> Callable[[float], float]:
    return lambda x: math.degrees(fn(x))


# name -> (number of arguments, function of floats)
FUNCTIONS: dict[str, tuple[int, Callable[..., float]]] = {
    "ABS": (1, abs),
    "SQR": (1, lambda x: x * x),
    "SQRT": (1, math.sqrt),
    "SIN": (1, _deg(math.sin)),
    "COS": (1, _deg(math.cos)),
    "TAN": (1, _deg(math.tan)),
    "ASIN": (1, _to_deg(math.asin)),
    "ACOS": (1, _to_deg(math.acos)),
    "ATAN": (1, _to_deg(math.atan)),
    "ATAN2": (2, lambda y, x: math.degrees(math.atan2(y, x))),
    "EXP": (1, math.exp),
    "LN": (1, math.log),
    "INT": (1, lambda x: float(math.trunc(x))),
    "ROUND": (1, lambda x: float(round_half_away(x))),
    "FRACT": (1, lambda x: x - math.trunc(x)),
}


# ------------------------------------------------------------------ closures


def fold(
    first: Node, rest: Sequence[tuple[Callable[[Value, Value], Value], Node, int]],
    line: LogicalLine,
) -> Node:
    """One closure for ``first op1 x1 op2 x2 ...`` evaluated left to right."""
    if isinstance(first, Const) and all(isinstance(x, Const) for _, x, _ in rest):
        try:
            value = first.value
            for op, x, _pos in rest:
                assert isinstance(x, Const)  # checked by the condition above
                value = op(value, x.value)
            return Const(value)
        except Fault:
            pass  # an error is raised when (and if) the expression is evaluated

    def folded(env: Any) -> Value:
        value = first(env)
        for op, x, pos in rest:
            try:
                value = op(value, x(env))
            except Fault as f:
                raise line.error(f.err_id, f.message, pos) from None
        return value

    return folded


def logic(first: Node, rest: list[tuple[int, Node]], stop_on: bool, line: LogicalLine) -> Node:
    """AND (stop_on False) / OR (stop_on True) with short-circuit evaluation."""
    operands = [(line_pos, node) for line_pos, node in rest]
    first_pos = operands[0][0]

    def logical(env: Any) -> Value:
        if truth(first(env), line, first_pos) == stop_on:
            return stop_on
        for pos, node in operands:
            if truth(node(env), line, pos) == stop_on:
                return stop_on
        return not stop_on

    return logical


def xor_op(a: Value, b: Value) -> Value:
    """Logical exclusive or of two numbers / TRUE-FALSE values."""
    if isinstance(a, str) or isinstance(b, str):
        raise Fault(NcErrorId.TYPE_MISMATCH, "XOR needs numbers or TRUE/FALSE")
    return (a != 0) != (b != 0)


def evaluate_number(node: Node | float, env: Env, line: LogicalLine, pos: int) -> float:
    """A word value: a parsed constant or an evaluated node, as a finite float."""
    value = node if isinstance(node, float) else number(node(env), line, pos)
    if not math.isfinite(value):
        raise line.error(NcErrorId.VALUE_OUT_OF_RANGE, f"value {value} is not a finite number", pos)
    return value
