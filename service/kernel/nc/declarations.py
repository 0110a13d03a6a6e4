"""``#VAR ... #ENDVAR``: reading the declaration lines and creating the variables.

Each line of the block declares one variable::

    V.L.COUNT                      REAL64, 0.0
    V.L.N : UNS32 = 200            typed, with initial value (any expression)
    V.L.A[3] : REAL64 = [1, 2, 3]  array with initializer list (shorter lists: the rest 0)
    V.L.M[2][2] = [[1, 2], [3, 4]] two dimensions
    V.L.B = [3, 212, 213]          a list without size declares an array of that size

An initializer list may continue on the following lines while its ``[`` are open.
The declarations run when the decoder reaches the block; running the same block again
(a loop, a second call) re-initialises its variables. Two different declarations of
one name in one scope are an error.
"""

from __future__ import annotations

import math
import re

from .call_stack import CallFrame, CallFrameKind
from .errors import NcErrorId
from .expressions import ExpressionParser, Node
from .lexer import IDENT, VARIABLE, Cursor
from .running_decoder import RunningDecoder
from .source import LogicalLine, join_lines
from .statements import Control, Declaration, InitList
from .variables import (
    Scope,
    Value,
    Variable,
    VariableFault,
    VarType,
    convert,
    default_value,
)

_ENDVAR = re.compile(r"[ \t]*#[ \t]*ENDVAR\b")
_UINT = re.compile(r"[0-9]+")
_STRING_LENGTH = re.compile(r"\[[ \t]*[0-9]+[ \t]*\]")
_DECL_SCOPES = {"L": Scope.L, "P": Scope.P, "G": Scope.G, "CYC": Scope.CYC}


def read_block(decoder: RunningDecoder, frame: CallFrame, stmt: Control,
               after: int) -> tuple[list[Declaration], int]:
    """The declarations of the ``#VAR`` block at ``frame.index`` and the index after it."""
    program = frame.program
    cached = program.var_blocks.get(frame.index)
    if cached is not None:
        return cached
    end = frame.section.end
    declarations: list[Declaration] = []
    k = after
    while True:
        if k >= end:
            raise stmt.line.error(
                NcErrorId.VAR_BLOCK_NOT_CLOSED, "#VAR without #ENDVAR", stmt.pos
            )
        line, k = program.logical(k, end)
        if line is None:
            continue
        if _ENDVAR.match(line.upper):
            break
        while _open_brackets(line.upper) > 0 and k < end:
            more, k_more = program.logical(k, end)
            if more is not None and _ENDVAR.match(more.upper):
                break
            k = k_more
            if more is not None:
                line = join_lines(line, more)
        declarations.append(parse_declaration(line))
    program.var_blocks[frame.index] = (declarations, k)
    return declarations, k


def parse_declaration(line: LogicalLine) -> Declaration:
    """One line inside ``#VAR ... #ENDVAR``: ``V.x.NAME[dims] [: TYPE] [= init]``."""
    cur = Cursor(line)
    cur.skip_ws()
    pos = cur.pos
    m = cur.match(VARIABLE)
    if m is None:
        raise cur.error(
            NcErrorId.INVALID_DECLARATION,
            f"variable declaration expected, found '{cur.word_text()}'",
        )
    scope = _DECL_SCOPES.get(m.group(1))
    if scope is None:
        raise cur.error(
            NcErrorId.VARIABLE_SCOPE_NOT_ALLOWED,
            f"V.{m.group(1)}. variables cannot be declared in #VAR", pos,
        )
    dims: list[int] = []
    while cur.peek() == "[":
        cur.pos += 1
        cur.skip_ws()
        size = cur.match(_UINT)
        cur.skip_ws()
        if size is None or cur.peek() != "]" or int(size.group()) == 0:
            raise cur.error(
                NcErrorId.INVALID_DECLARATION, "array size must be a positive integer"
            )
        cur.pos += 1
        dims.append(int(size.group()))
    vtype = VarType.REAL64
    cur.skip_ws()
    if cur.peek() == ":":
        cur.pos += 1
        cur.skip_ws()
        tpos = cur.pos
        t = cur.match(IDENT)
        if t is None or t.group() not in VarType.__members__:
            raise cur.error(
                NcErrorId.UNKNOWN_TYPE, f"unknown type '{cur.word_text(tpos)}'", tpos
            )
        vtype = VarType[t.group()]
        if vtype == VarType.STRING and cur.peek() == "[":
            if cur.match(_STRING_LENGTH) is None:
                raise cur.error(NcErrorId.INVALID_DECLARATION, "STRING[n] needs a length")
    init: Node | InitList | None = None
    cur.skip_ws()
    if cur.peek() == "=":
        cur.pos += 1
        cur.skip_ws()
        init = _initializer(cur) if cur.peek() == "[" else ExpressionParser(cur).parse()
    if not cur.at_end():
        raise cur.unexpected(f"in the declaration of V.{m.group(1)}.{m.group(2)}")
    return Declaration(scope, m.group(2), vtype, tuple(dims), init, line, pos)

def _initializer(cur: Cursor) -> Node | InitList:
    """``[a, b, [c, d]]`` (nested lists of expressions) or one bracketed expression."""
    items: InitList = []
    cur.pos += 1  # '['
    parser = ExpressionParser(cur)
    while True:
        cur.skip_ws()
        items.append(_initializer(cur) if cur.peek() == "[" else parser.parse())
        cur.skip_ws()
        if cur.peek() == ",":
            cur.pos += 1
            continue
        parser.expect("]")
        break
    return items


def _open_brackets(text: str) -> int:
    return text.count("[") - text.count("]")


def declare(decoder: RunningDecoder, frame: CallFrame, decl: Declaration) -> None:
    """Create (or re-initialise) the variable of one declaration."""
    modal = decoder.modal
    line = decl.line
    full = f"V.{decl.scope.name}.{decl.name}"
    if decl.scope == Scope.L:
        table = frame.local_vars
    elif decl.scope == Scope.CYC:
        table = frame.cycle_vars
    elif decl.scope == Scope.P:
        if frame.kind != CallFrameKind.MAIN:
            raise line.error(
                NcErrorId.VARIABLE_SCOPE_NOT_ALLOWED,
                f"{full}: V.P. variables can only be declared in the main program", decl.pos,
            )
        table = modal.variables_p
    else:
        table = modal.variables_g
    site = (line.file, line.index)
    existing = table.get(decl.name)
    if existing is not None:
        if decl.scope == Scope.G:
            return  # a global exists once; its value survives
        earlier_decoder = decl.scope == Scope.P and id(existing) not in decoder.own_variables
        if existing.site != site and not earlier_decoder:
            raise line.error(
                NcErrorId.VARIABLE_DECLARED_TWICE,
                f"{full} is already declared (line {existing.site[1] + 1})", decl.pos,
            )
    variable = _create(decoder, decl, full, site)
    table[decl.name] = variable
    decoder.own_variables.add(id(variable))


def _create(
    decoder: RunningDecoder, decl: Declaration, full: str, site: tuple[str, int],
) -> Variable:
    line = decl.line
    init = decl.init
    dims = decl.dims
    values: list[Value]
    if isinstance(init, list) and not dims:
        if len(init) == 1 and not isinstance(init[0], list):
            init = init[0]  # "= [expr]" is a bracketed expression
        else:
            dims = _shape(init)
    try:
        if dims:
            size = math.prod(dims)
            values = [default_value(decl.vtype)] * size
            if init is not None:
                if not isinstance(init, list):
                    raise VariableFault(
                        NcErrorId.INVALID_DECLARATION,
                        f"{full} is an array: initialise it with [..]",
                    )
                flat = _flatten(init, dims, full)
                for n, node in enumerate(flat):
                    if node is not _DEFAULT_NODE:
                        values[n] = convert(decl.vtype, node(decoder), full)
        else:
            # a list without dims became the dims above, or was one bracketed expression
            assert not isinstance(init, list)
            value: Value = default_value(decl.vtype) if init is None else init(decoder)
            values = [convert(decl.vtype, value, full)]
    except VariableFault as f:
        raise line.error(f.err_id, f.message, decl.pos) from None
    return Variable(full, decl.vtype, tuple(dims), values, site)


def _shape(items: InitList) -> tuple[int, ...]:
    """Dimensions of a (possibly nested) initializer list."""
    if items and isinstance(items[0], list):
        return (len(items), *_shape(items[0]))
    return (len(items),)


def _flatten(items: InitList, dims: tuple[int, ...], full: str) -> list[Node]:
    """Row-major list of nodes; each level may be shorter than its dimension."""
    if len(items) > dims[0]:
        raise VariableFault(
            NcErrorId.INVALID_DECLARATION, f"{full}: {len(items)} values for {dims[0]} elements"
        )
    if len(dims) == 1:
        nodes = [x for x in items if not isinstance(x, list)]
        if len(nodes) != len(items):
            raise VariableFault(NcErrorId.INVALID_DECLARATION, f"{full}: too many [ levels")
        return nodes
    inner = math.prod(dims[1:])
    flat: list[Node] = []
    for row in items:
        if not isinstance(row, list):
            raise VariableFault(NcErrorId.INVALID_DECLARATION, f"{full}: a row must be a [list]")
        part = _flatten(row, dims[1:], full)
        flat.extend(part)
        flat.extend([_DEFAULT_NODE] * (inner - len(part)))
    return flat


class _Default:
    """Placeholder for an element without initial value (keeps the type default)."""

    def __call__(self, env: object) -> Value:
        raise AssertionError("never evaluated")


_DEFAULT_NODE = _Default()

__all__ = ["VarType", "declare", "parse_declaration", "read_block"]
