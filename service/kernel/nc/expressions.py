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
    primary := number | "string" | TRUE | FALSE | variable | @P<n> | FUNC[args] | [ or ]

Functions: ABS SQR SQRT SIN COS TAN ASIN ACOS ATAN ATAN2 EXP LN INT ROUND FRACT, each
called with brackets: ``SIN[30]``. The parser builds the nodes of ``evaluation``;
constant sub-expressions are computed when parsed (an error in them is left for the
evaluation, so ``0 AND 1/0`` is FALSE). Nesting is limited to ``MAX_DEPTH`` levels, so a
line of 10,000 ``[`` is an error and never exhausts Python's stack.
"""

from __future__ import annotations

import re
from typing import Any

from .errors import NcError, NcErrorId
from .evaluation import (
    ADD_OPS,
    CMP_OPS,
    CMP_SYMBOLS,
    FUNCTIONS,
    MUL_OPS,
    Const,
    Node,
    ParamRef,
    VarRef,
    evaluate_number,
    fold,
    logic,
    number,
    pow_op,
    truth,
    xor_op,
)
from .lexer import IDENT, NUMBER, VARIABLE, Cursor
from .variables import Scope, Value

_PARAM_REF = re.compile(r"@P([0-9]+)")
# V.G. variables with members that the decoder provides (they are not declared)
_MEMBER_NAMES = frozenset({"HSCS", "WZ_AKT"})
_MEMBER = re.compile(r"(?:\.[A-Z_][A-Z0-9_]*)+")
_NP_MEMBER = re.compile(r"\.V(?:\.[A-Z_][A-Z0-9_]*)?")  # .V.X or .V (then [i])
MAX_DEPTH = 32  # nesting of brackets / unary operators; keeps Python's stack small

_SCOPES = {"L": Scope.L, "P": Scope.P, "G": Scope.G, "CYC": Scope.CYC}


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

    def _indices(self, into: list[Node]) -> None:
        """Each ``[expr]`` at the cursor, appended to ``into`` (a variable's indices)."""
        cur = self.cur
        while cur.peek() == "[":
            open_pos = cur.pos
            cur.pos += 1
            self._enter()
            into.append(self._or())
            self.depth -= 1
            self.expect("]", open_pos)

    def _keyword(self, *words: str) -> str | None:
        """The keyword operator at the cursor (whole identifier only), consumed."""
        cur = self.cur
        cur.skip_ws()
        c = cur.peek()
        if not ("A" <= c <= "Z"):  # no identifier here: spare the match (hot in long lines)
            return None
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
        return logic(first, rest, True, self.line) if rest else first

    def _xor(self) -> Node:
        first = self._and()
        rest = []
        while True:
            pos = self._op_pos()
            if self._keyword("XOR") is None:
                break
            rest.append((xor_op, self._and(), pos))
        return fold(first, rest, self.line) if rest else first

    def _and(self) -> Node:
        first = self._not()
        rest: list[tuple[int, Node]] = []
        while True:
            pos = self._op_pos()
            if self._keyword("AND") is None:
                break
            rest.append((pos, self._not()))
        return logic(first, rest, False, self.line) if rest else first

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
            op = self._symbol(CMP_SYMBOLS)
            if op is None:
                break
            rest.append((CMP_OPS[op], self._add(), pos))
        return fold(first, rest, self.line) if rest else first

    def _add(self) -> Node:
        first = self._mul()
        rest = []
        while True:
            pos = self._op_pos()
            op = self._symbol(("+", "-"))
            if op is None:
                break
            rest.append((ADD_OPS[op], self._mul(), pos))
        return fold(first, rest, self.line) if rest else first

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
            rest.append((MUL_OPS[op], self._unary(), pos))
        return fold(first, rest, self.line) if rest else first

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
        return fold(Const(0.0), [(ADD_OPS["-"], operand, pos)], self.line)

    def _power(self) -> Node:
        base = self._primary()
        pos = self._op_pos()
        if self._symbol(("**", "^")) is None:
            return base
        self._enter()
        exponent = self._unary()
        self.depth -= 1
        return fold(base, [(pow_op, exponent, pos)], self.line)

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
        if c == "@":
            m = cur.match(_PARAM_REF)
            if m is None:
                raise cur.error(NcErrorId.EXPRESSION_SYNTAX,
                                f"unexpected '{cur.word_text()}' in expression: cycle "
                                "parameters are written @P<n>")
            return ParamRef(int(m.group(1)), self.line, pos)
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
        spec = FUNCTIONS.get(name)
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
            if m.group(1) == "E":  # external variables link to the PLC; none are configured
                raise cur.error(
                    NcErrorId.UNKNOWN_VARIABLE,
                    f"unknown variable V.E.{m.group(2)}: no external variable of that name "
                    "(this kernel configures no V.E. variables)", pos,
                )
            raise cur.error(
                NcErrorId.VARIABLE_SCOPE_NOT_ALLOWED,
                f"V.{m.group(1)}. variables are not supported yet", pos,
            )
        indices: list[Node] = []
        self._indices(indices)
        name = m.group(2)
        if scope == Scope.G and name in _MEMBER_NAMES and cur.peek() == ".":
            member = cur.match(_MEMBER)  # V.G.HSCS.<MODE>.TOLERANCE, V.G.WZ_AKT.R
            if member is not None:
                name += member.group()
        if scope == Scope.G and name == "NP" and cur.peek() == ".":
            # V.G.NP[j].V.<axis> / V.G.NP[j].V[i]: zero offset j of one axis (issue 39)
            member = cur.match(_NP_MEMBER)
            if member is not None:
                name += member.group()
                self._indices(indices)
        if cur.peek() == ".":
            raise cur.error(
                NcErrorId.INSTRUCTION_NOT_SUPPORTED,
                f"structure member access ({cur.word_text(pos)}) is not supported yet", pos,
            )
        return VarRef(scope, name, tuple(indices), self.line, pos)


def parse_expression(cur: Cursor) -> Node:
    """Parse one expression at the cursor."""
    return ExpressionParser(cur).parse()



__all__ = [
    "Const", "ExpressionParser", "Node", "VarRef", "evaluate_number", "number",
    "parse_expression", "truth",
]
