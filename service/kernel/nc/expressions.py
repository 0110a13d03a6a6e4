"""Arithmetic and logic expressions: parsed once per line, evaluated each time it runs.

Grammar (lowest precedence first; ``( )`` are comments in ISG, so ``[ ]`` group)::

    or      := xor  { OR xor }
    xor     := and  { XOR and }
    and     := not  { AND not }
    not     := NOT not | cmp
    cmp     := add  { (== | != | <> | < | > | <= | >=) add }
    add     := mul  { (+ | -) mul }
    mul     := unary { (* | / | MOD) unary }
    unary   := (- | +) unary | power
    power   := primary [ (** | ^) unary ]          right associative
    primary := number | "string" | TRUE | FALSE | variable | FUNC[args] | [ or ]

Functions: ABS SQR SQRT SIN COS TAN ASIN ACOS ATAN ATAN2 EXP LN INT ROUND FRACT (angles
in degrees; INT truncates toward zero; ROUND rounds halves away from zero; FRACT is
x - INT[x]). Comparisons give TRUE/FALSE; AND/OR evaluate their right side only when
needed. Numbers are floats; ``**`` is computed with ``math.pow`` so huge powers are an
error instead of a giant integer.

A parsed expression is a callable ``node(env)`` where ``env`` finds variables
(``env.find_variable(scope, name)``). Operator chains of one level compile to one
closure that folds over its operands, so a long ``1+1+...+1`` does not nest Python
calls; bracket nesting is limited to ``MAX_DEPTH``. Constant sub-expressions are folded
when parsed.
"""

from __future__ import annotations

import math
import operator
from collections.abc import Callable
from typing import Any, Protocol

from .errors import NcError, NcErrorId
from .lexer import IDENT, NUMBER, VARIABLE, Cursor
from .source import LogicalLine
from .variables import Scope, Value, Variable, VariableFault, round_half_away

MAX_DEPTH = 32  # nesting of brackets / unary operators; keeps Python's stack small

Node = Callable[[Any], Value]
Fault = VariableFault


class Env(Protocol):
    """What evaluation needs from the interpreter."""

    def find_variable(self, scope: Scope, name: str) -> Variable | None:
        """The visible variable ``V.<scope>.<name>`` or None."""


class Const:
    """A node whose value is known when parsed."""

    __slots__ = ("value",)

    def __init__(self, value: Value) -> None:
        self.value = value

    def __call__(self, env: Any) -> Value:
        return self.value


_SCOPES = {"L": Scope.L, "P": Scope.P, "G": Scope.G, "CYC": Scope.CYC}


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

    def _resolve(self, env: Any) -> tuple[Variable, tuple[int, ...]]:
        var = env.find_variable(self.scope, self.name)
        if var is None:
            raise self.line.error(
                NcErrorId.UNDECLARED_VARIABLE, f"undeclared variable {self.full}", self.pos
            )
        if not self.indices:
            return var, ()
        return var, tuple(_index(node(env), self.line, self.pos) for node in self.indices)

    def __call__(self, env: Any) -> Value:
        var, indices = self._resolve(env)
        try:
            return var.get(indices)
        except Fault as f:
            raise self.line.error(f.err_id, f.message, self.pos) from None

    def assign(self, env: Any, value: Value) -> None:
        """Store ``value`` (converted to the variable's type)."""
        var, indices = self._resolve(env)
        try:
            var.set(value, indices)
        except Fault as f:
            raise self.line.error(f.err_id, f.message, self.pos) from None


def _index(value: Value, line: LogicalLine, pos: int) -> int:
    if isinstance(value, str) or value != int(value):
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


def _numbers(a: Value, b: Value, op: str) -> None:
    if isinstance(a, str) or isinstance(b, str):
        raise Fault(NcErrorId.TYPE_MISMATCH, f"operator {op} needs numbers")


def _add(a: Value, b: Value) -> Value:
    if isinstance(a, str) and isinstance(b, str):
        return a + b
    _numbers(a, b, "+")
    return a + b


def _arith(op: str, fn: Callable[[Any, Any], Value]) -> Callable[[Value, Value], Value]:
    def apply(a: Value, b: Value) -> Value:
        _numbers(a, b, op)
        return fn(a, b)

    return apply


def _div(a: Value, b: Value) -> Value:
    _numbers(a, b, "/")
    if b == 0:
        raise Fault(NcErrorId.DIVISION_BY_ZERO, "division by zero")
    return a / b


def _mod(a: Value, b: Value) -> Value:
    _numbers(a, b, "MOD")
    if b == 0:
        raise Fault(NcErrorId.DIVISION_BY_ZERO, "division by zero (MOD 0)")
    return math.fmod(a, b)


def _pow(a: Value, b: Value) -> Value:
    _numbers(a, b, "**")
    try:
        return math.pow(a, b)
    except (ValueError, OverflowError):
        raise Fault(NcErrorId.MATH_DOMAIN, f"{a:g} ** {b:g} is not defined or too large") from None


def _compare(op: str, fn: Callable[[Any, Any], bool]) -> Callable[[Value, Value], Value]:
    def apply(a: Value, b: Value) -> Value:
        if isinstance(a, str) != isinstance(b, str):
            raise Fault(NcErrorId.TYPE_MISMATCH, f"cannot compare a string with a number ({op})")
        if isinstance(a, str) and op not in ("==", "!=", "<>"):
            raise Fault(NcErrorId.TYPE_MISMATCH, f"strings can only be compared with == and !=")
        return fn(a, b)

    return apply


_ADD_OPS = {"+": _add, "-": _arith("-", operator.sub)}
_MUL_OPS = {"*": _arith("*", operator.mul), "/": _div, "MOD": _mod}
_CMP_OPS = {
    "==": _compare("==", operator.eq), "!=": _compare("!=", operator.ne),
    "<>": _compare("<>", operator.ne), "<=": _compare("<=", operator.le),
    ">=": _compare(">=", operator.ge), "<": _compare("<", operator.lt),
    ">": _compare(">", operator.gt),
}
_CMP_SYMBOLS = ("==", "!=", "<>", "<=", ">=", "<", ">")


def _deg(fn: Callable[[float], float]) -> Callable[[float], float]:
    return lambda x: fn(math.radians(x))


def _to_deg(fn: Callable[[float], float]) -> Callable[[float], float]:
    return lambda x: math.degrees(fn(x))


# name -> (number of arguments, function of floats)
_FUNCTIONS: dict[str, tuple[int, Callable[..., float]]] = {
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


def _fold(first: Node, rest: list[tuple[Callable, Node, int]], line: LogicalLine) -> Node:
    """One closure for ``first op1 x1 op2 x2 ...`` evaluated left to right."""
    if isinstance(first, Const) and all(isinstance(x, Const) for _, x, _ in rest):
        try:
            value = first.value
            for op, x, pos in rest:
                value = op(value, x.value)
            return Const(value)
        except Fault:
            pass  # an error is raised when (and if) the expression is evaluated

    def fold(env: Any) -> Value:
        value = first(env)
        for op, x, pos in rest:
            try:
                value = op(value, x(env))
            except Fault as f:
                raise line.error(f.err_id, f.message, pos) from None
        return value

    return fold


def _logic(first: Node, rest: list[tuple[int, Node]], stop_on: bool, line: LogicalLine) -> Node:
    """AND (stop_on False) / OR (stop_on True) with short-circuit evaluation."""
    operands = [(line_pos, node) for line_pos, node in rest]
    first_pos = operands[0][0]

    def logic(env: Any) -> Value:
        if truth(first(env), line, first_pos) == stop_on:
            return stop_on
        for pos, node in operands:
            if truth(node(env), line, pos) == stop_on:
                return stop_on
        return not stop_on

    return logic


# ------------------------------------------------------------------ parser


class ExpressionParser:
    """Recursive descent over a Cursor; see the module docstring for the grammar."""

    def __init__(self, cur: Cursor) -> None:
        self.cur = cur
        self.line = cur.line
        self.depth = 0

    def parse(self) -> Node:
        """One expression starting at the cursor (blanks allowed before it)."""
        return self._or()

    # -- helpers

    def _enter(self) -> None:
        self.depth += 1
        if self.depth > MAX_DEPTH:
            raise self.cur.error(
                NcErrorId.EXPRESSION_TOO_COMPLEX,
                f"expression nested deeper than {MAX_DEPTH} levels",
            )

    def _keyword(self, *words: str) -> str | None:
        """The keyword operator at the cursor (whole identifier only), consumed."""
        cur = self.cur
        cur.skip_ws()
        m = IDENT.match(cur.up, cur.pos)
        if m is not None and m.group() in words:
            cur.pos = m.end()
            return m.group()
        return None

    def _symbol(self, symbols: tuple[str, ...]) -> str | None:
        cur = self.cur
        cur.skip_ws()
        for s in symbols:
            if cur.up.startswith(s, cur.pos):
                cur.pos += len(s)
                return s
        return None

    # -- levels

    def _or(self) -> Node:
        first = self._xor()
        rest: list[tuple[int, Node]] = []
        while True:
            pos = self._op_pos()
            if self._keyword("OR") is None:
                break
            rest.append((pos, self._xor()))
        return _logic(first, rest, True, self.line) if rest else first

    def _xor(self) -> Node:
        first = self._and()
        rest = []
        while True:
            pos = self._op_pos()
            if self._keyword("XOR") is None:
                break
            rest.append((_xor_op, self._and(), pos))
        return _fold(first, rest, self.line) if rest else first

    def _and(self) -> Node:
        first = self._not()
        rest: list[tuple[int, Node]] = []
        while True:
            pos = self._op_pos()
            if self._keyword("AND") is None:
                break
            rest.append((pos, self._not()))
        return _logic(first, rest, False, self.line) if rest else first

    def _not(self) -> Node:
        pos = self._op_pos()
        if self._keyword("NOT") is None:
            return self._cmp()
        self._enter()
        operand = self._not()
        self.depth -= 1
        line = self.line
        if isinstance(operand, Const) and not isinstance(operand.value, str):
            return Const(operand.value == 0)
        return lambda env: not truth(operand(env), line, pos)

    def _cmp(self) -> Node:
        first = self._add()
        rest = []
        while True:
            pos = self._op_pos()
            if self.cur.startswith("=") and not self.cur.startswith("=="):
                break  # a single '=' ends the expression (assignment or an error upstream)
            op = self._symbol(_CMP_SYMBOLS)
            if op is None:
                break
            rest.append((_CMP_OPS[op], self._add(), pos))
        return _fold(first, rest, self.line) if rest else first

    def _add(self) -> Node:
        first = self._mul()
        rest = []
        while True:
            pos = self._op_pos()
            op = self._symbol(("+", "-"))
            if op is None:
                break
            rest.append((_ADD_OPS[op], self._mul(), pos))
        return _fold(first, rest, self.line) if rest else first

    def _mul(self) -> Node:
        first = self._unary()
        rest = []
        while True:
            pos = self._op_pos()
            if self.cur.startswith("**"):
                break
            op = self._symbol(("*", "/")) or self._keyword("MOD")
            if op is None:
                break
            rest.append((_MUL_OPS[op], self._unary(), pos))
        return _fold(first, rest, self.line) if rest else first

    def _unary(self) -> Node:
        pos = self._op_pos()
        op = self._symbol(("-", "+"))
        if op is None:
            return self._power()
        self._enter()
        operand = self._unary()
        self.depth -= 1
        if op == "+":
            return operand
        return _fold(Const(0.0), [(_ADD_OPS["-"], operand, pos)], self.line)

    def _power(self) -> Node:
        base = self._primary()
        pos = self._op_pos()
        if self._symbol(("**", "^")) is None:
            return base
        self._enter()
        exponent = self._unary()
        self.depth -= 1
        return _fold(base, [(_pow, exponent, pos)], self.line)

    def _op_pos(self) -> int:
        self.cur.skip_ws()
        return self.cur.pos

    def _primary(self) -> Node:
        cur = self.cur
        cur.skip_ws()
        pos = cur.pos
        c = cur.peek()
        if c == "[":
            cur.pos += 1
            self._enter()
            node = self._or()
            self.depth -= 1
            self.expect("]", pos)
            return node
        if c == '"':
            return Const(self._string())
        m = cur.match(NUMBER)
        if m is not None:
            return Const(float(m.group()))
        if c == "V" and cur.peek(1) == ".":
            return self.variable()
        m = cur.match(IDENT)
        if m is not None:
            word = m.group()
            if word == "TRUE":
                return Const(True)
            if word == "FALSE":
                return Const(False)
            cur.skip_ws()
            if cur.peek() == "[":
                return self._call(word, pos)
            cur.pos = pos
            raise cur.error(
                NcErrorId.EXPRESSION_SYNTAX, f"unexpected '{cur.word_text()}' in expression"
            )
        if cur.at_end():
            raise cur.error(NcErrorId.EXPRESSION_SYNTAX, "expression expected")
        raise cur.error(
            NcErrorId.EXPRESSION_SYNTAX, f"unexpected '{cur.word_text()}' in expression"
        )

    def expect(self, symbol: str, opened_at: int | None = None) -> None:
        """Consume ``symbol`` or raise an error naming it."""
        cur = self.cur
        cur.skip_ws()
        if cur.startswith(symbol):
            cur.pos += len(symbol)
            return
        what = f"'{symbol}' expected"
        if opened_at is not None and symbol == "]":
            line, col = self.line.locate(opened_at)
            what = f"']' expected to close the '[' at column {col}"
        if cur.pos >= cur.end:
            raise cur.error(NcErrorId.EXPRESSION_SYNTAX, f"{what}, found the end of the line")
        raise cur.error(NcErrorId.EXPRESSION_SYNTAX, f"{what}, found '{cur.word_text()}'")

    def _string(self) -> str:
        cur = self.cur
        start = cur.pos
        close = cur.text.find('"', start + 1)
        if close < 0:
            raise cur.error(NcErrorId.STRING_NOT_CLOSED, "string without closing '\"'", start)
        cur.pos = close + 1
        return cur.text[start + 1 : close]

    def _call(self, name: str, pos: int) -> Node:
        cur = self.cur
        spec = _FUNCTIONS.get(name)
        if spec is None:
            raise cur.error(NcErrorId.UNKNOWN_FUNCTION, f"unknown function {name}", pos)
        count, fn = spec
        open_pos = cur.pos
        cur.pos += 1  # '['
        self._enter()
        args = [self._or()]
        while self._symbol((",",)) is not None:
            args.append(self._or())
        self.depth -= 1
        self.expect("]", open_pos)
        if len(args) != count:
            raise cur.error(
                NcErrorId.EXPRESSION_SYNTAX,
                f"{name} takes {count} argument(s), got {len(args)}", pos,
            )
        line = self.line

        def call(env: Any) -> Value:
            values = [number(a(env), line, pos, f"a number for {name}") for a in args]
            try:
                result = fn(*values)
            except (ValueError, OverflowError, ArithmeticError):
                shown = ", ".join(f"{v:g}" for v in values)
                raise line.error(
                    NcErrorId.MATH_DOMAIN, f"{name}[{shown}] is not defined or too large", pos
                ) from None
            return float(result)

        if all(isinstance(a, Const) for a in args):
            try:
                return Const(call(None))
            except NcError:
                pass  # raised when (and if) the expression is evaluated
        return call

    def variable(self) -> VarRef:
        """``V.<scope>.<name>`` with optional ``[index]`` parts."""
        cur = self.cur
        cur.skip_ws()
        pos = cur.pos
        m = cur.match(VARIABLE)
        if m is None:
            raise cur.error(NcErrorId.EXPRESSION_SYNTAX, "variable name expected after 'V.'")
        scope = _SCOPES.get(m.group(1))
        if scope is None:
            raise cur.error(
                NcErrorId.VARIABLE_SCOPE_NOT_ALLOWED,
                f"V.{m.group(1)}. variables are not supported yet", pos,
            )
        indices = []
        while cur.peek() == "[":
            open_pos = cur.pos
            cur.pos += 1
            self._enter()
            indices.append(self._or())
            self.depth -= 1
            self.expect("]", open_pos)
        if cur.peek() == ".":
            raise cur.error(
                NcErrorId.INSTRUCTION_NOT_SUPPORTED,
                f"structure member access ({cur.word_text(pos)}) is not supported yet", pos,
            )
        return VarRef(scope, m.group(2), tuple(indices), self.line, pos)


def _xor_op(a: Value, b: Value) -> Value:
    if isinstance(a, str) or isinstance(b, str):
        raise Fault(NcErrorId.TYPE_MISMATCH, "XOR needs numbers or TRUE/FALSE")
    return (a != 0) != (b != 0)


def parse_expression(cur: Cursor) -> Node:
    """Parse one expression at the cursor."""
    return ExpressionParser(cur).parse()


def evaluate_number(node: Node | float, env: Any, line: LogicalLine, pos: int) -> float:
    """A word value: a parsed constant or an evaluated node, as a finite float."""
    value = node if isinstance(node, float) else number(node(env), line, pos)
    if not math.isfinite(value):
        raise line.error(NcErrorId.VALUE_OUT_OF_RANGE, f"value {value} is not a finite number", pos)
    return value


__all__ = [
    "Const", "Env", "ExpressionParser", "NcError", "Node", "VarRef", "evaluate_number",
    "number", "parse_expression", "truth",
]
