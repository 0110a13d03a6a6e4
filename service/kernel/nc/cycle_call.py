"""Parsing a cycle call: ``L CYCLE [NAME=<name> @P<n>=<expr> ... ]``.

The call stands in an NC block like ``L name`` and is usually spread over continuation
lines (``\\`` at the end of each line, ``source``). Inside the brackets, in any order:

* ``NAME = <name>`` or ``NAME = "<name>"``: the cycle (``SysCalcCircle.ecy``, a user
  cycle file of the program store, or with ``LL CYCLE`` a ``%L`` section of the file);
* ``@P<n> = <expr>``: parameter n (an expression: numbers, strings, variables);
* ``PATTERN_ID = <expr>`` and ``PATTERN_RETRACT = <expr>``: run the cycle at every
  position of a call pattern (``#PATTERN``).

Each key may appear once. The values are evaluated when the call runs, in the caller.
"""

from __future__ import annotations

import re

from .errors import NcErrorId
from .expressions import ExpressionParser, Node
from .lexer import Cursor
from .statements import Call, CycleArgs, CycleParam

CYCLE_WORD = re.compile(r"CYCLE[ \t]*\[")  # after L / LL: a cycle call, not a file "CYCLE"
_PARAM = re.compile(r"@P([0-9]+)")
_KEY = re.compile(r"[A-Z_][A-Z0-9_]*")
_NAME_VALUE = re.compile(r"[^ \t\f\v\]]+")
MAX_PARAMETER = 999  # @P1 .. @P999


def parse_cycle_call(cur: Cursor, local: bool, call_pos: int) -> Call:
    """The call at the cursor, which stands on ``CYCLE``; ``call_pos``: the ``L``."""
    open_pos = cur.up.index("[", cur.pos)
    cur.pos = open_pos + 1
    name: str | None = None
    name_pos = -1
    params: dict[int, CycleParam] = {}
    extra: dict[str, tuple[Node, int]] = {}  # PATTERN_ID=.. -> (value, position)
    seen: dict[str, int] = {}
    expr = ExpressionParser(cur)
    while True:
        cur.skip_ws()
        pos = cur.pos
        if cur.pos >= cur.end:
            raise cur.error(NcErrorId.CYCLE_SYNTAX,
                            "']' expected to close L CYCLE [ (end a continued line with '\\')",
                            open_pos)
        if cur.peek() == "]":
            cur.pos += 1
            break
        m = cur.match(_PARAM)
        if m is not None:
            number = int(m.group(1))
            if not 1 <= number <= MAX_PARAMETER:
                raise cur.error(NcErrorId.CYCLE_PARAMETER_UNKNOWN,
                                f"@P{number}: cycle parameters are @P1..@P{MAX_PARAMETER}", pos)
            key = f"@P{number}"
        else:
            m = cur.match(_KEY)
            key = m.group() if m is not None else ""
            if key not in ("NAME", "PATTERN_ID", "PATTERN_RETRACT"):
                cur.pos = pos
                raise cur.error(
                    NcErrorId.CYCLE_SYNTAX,
                    f"unexpected '{cur.word_text()}' in L CYCLE [...]: expected NAME=, "
                    "@P<n>=, PATTERN_ID= or PATTERN_RETRACT=", pos)
        if key in seen:
            raise cur.error(NcErrorId.CYCLE_PARAMETER_TWICE, f"{key} given twice in one cycle "
                            f"call (first at column {cur.line.locate(seen[key])[1]})", pos)
        seen[key] = pos
        cur.skip_ws()
        if cur.peek() != "=":
            raise cur.error(NcErrorId.CYCLE_SYNTAX, f"'=' expected after {key}")
        cur.pos += 1
        cur.skip_ws()
        if key == "NAME":
            name_pos = cur.pos
            name = _name_value(cur)
        elif key.startswith("@P"):
            params[number] = CycleParam(number, expr.parse(), pos)
        else:
            extra[key] = (expr.parse(), pos)
    if name is None:
        raise cur.error(NcErrorId.CYCLE_SYNTAX, "L CYCLE [...] needs NAME=<cycle>", call_pos)
    args = CycleArgs(tuple(params[n] for n in sorted(params)))
    if "PATTERN_ID" in extra:
        args.pattern_id, args.pattern_id_pos = extra["PATTERN_ID"]
    if "PATTERN_RETRACT" in extra:
        args.pattern_retract, args.pattern_retract_pos = extra["PATTERN_RETRACT"]
    return Call(local, name, name_pos, args)


def _name_value(cur: Cursor) -> str:
    pos = cur.pos
    if cur.peek() == '"':
        close = cur.text.find('"', pos + 1)
        if close < 0:
            raise cur.error(NcErrorId.STRING_NOT_CLOSED, "string without closing '\"'", pos)
        cur.pos = close + 1
        name = cur.text[pos + 1:close].strip()
    else:
        m = _NAME_VALUE.match(cur.text, pos)
        name = m.group() if m else ""
        cur.pos = m.end() if m else pos
    if not name:
        raise cur.error(NcErrorId.CYCLE_SYNTAX, "cycle name expected after NAME=", pos)
    return name
