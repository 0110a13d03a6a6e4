"""Contour look-ahead (ISG FCT-C40) and path-distance commands: parsing and executing.

* ``#CONTOUR LOOKAHEAD LOG ON`` / ``... LOG OFF`` open and close the marked area whose
  contour elements the kernel hands to the PLC in advance; both take an optional
  ``[PARAM=<expr>]`` (or the bare ``PARAM=<expr>``), a user value put into the log.
* ``#CONTOUR LOOKAHEAD LOG [PARAM=<expr>]`` adds a PARAM entry to the log.
* ``#CONTOUR LOOKAHEAD LOG CLEAR`` empties the log (the path stops there: flush and
  wait); not allowed inside ``#RT WHILE`` (error 22073, as on ISG).
* ``#DISTANCE PROG START CLEAR`` (also spelled ``#DISTANCE PROGRAM START CLEAR``)
  restarts the path distance from the program start at 0.

Each command stands alone in its NC line (an N number and a label may precede it) and
gives one Block without motion whose ``contour`` says what to do; the kernel side
decides what is logged. ``#CONTOUR LOOKAHEAD`` needs the channel's contour look-ahead
function (``Decoder(contour_lookahead=True)``: FCT_CONTOUR_LAH in P-CHAN-00650);
``#DISTANCE`` works without it. PARAM is evaluated when the command is decoded.

The LOG commands move ``ModalState.contour_log_area`` (``blocks.next_log_area``): only
the first marked area counts until LOG CLEAR.

Real-time loops: ISG logs the body of a ``#RT WHILE`` loop three times (start of loop,
loop to loop, end of loop) when the loop starts inside an open marked area. The decoder
unrolls such loops, so it tells the kernel where the passes are with marker Blocks
(``rt_loop_markers``): RT_PASS before each pass, RT_END after the last one. Only the
outermost such loop is tracked; a loop entered while the area is not open never gets
markers, so a program without the contour look-ahead gives the blocks it always gave.

This module holds the words and their parsing (the parser needs it); running a command
is ``contour_run``, the markers are ``rt_loop_markers``.
"""

from __future__ import annotations

import re

from .blocks import ContourKind
from .errors import NcError, NcErrorId
from .expressions import ExpressionParser, Node
from .lexer import IDENT, Cursor
from .statements import ContourStatement

# "#CONTOUR" / "#DISTANCE" where it does not start the line (another word before it)
CONTOUR_WORD = re.compile(r"#[ \t]*(?:CONTOUR|DISTANCE)\b")
# the marker kinds: not NC blocks of the program (the endless-loop guard ignores them)
LOOP_MARKERS = frozenset({ContourKind.RT_PASS, ContourKind.RT_END})

_LOG_WORDS = {"ON": ContourKind.LOG_ON, "OFF": ContourKind.LOG_OFF,
              "CLEAR": ContourKind.LOG_CLEAR}
_SPELLING = {
    ContourKind.LOG_ON: "#CONTOUR LOOKAHEAD LOG ON",
    ContourKind.LOG_PARAM: "#CONTOUR LOOKAHEAD LOG [PARAM=..]",
    ContourKind.LOG_OFF: "#CONTOUR LOOKAHEAD LOG OFF",
    ContourKind.LOG_CLEAR: "#CONTOUR LOOKAHEAD LOG CLEAR",
    ContourKind.DISTANCE_CLEAR: "#DISTANCE PROG START CLEAR",
}


# ------------------------------------------------------------------ parsing


def parse_contour_command(cur: Cursor, hash_pos: int, word: str,
                          number: int | None) -> ContourStatement:
    """The ``#CONTOUR`` or ``#DISTANCE`` (``word``) command whose ``#`` is at
    ``hash_pos``; the cursor stands after the word. Malformed: CONTOUR_COMMAND_SYNTAX."""
    if word == "DISTANCE":
        stmt = _distance(cur, hash_pos, number)
    else:
        stmt = _contour(cur, hash_pos, number)
    if not cur.at_end():
        raise _syntax(cur, f"{_SPELLING[stmt.kind]} must stand alone in its NC line, "
                           f"found '{cur.word_text()}'")
    return stmt


def _distance(cur: Cursor, hash_pos: int, number: int | None) -> ContourStatement:
    prog = _word(cur, ("PROG", "PROGRAM"), "#DISTANCE")
    _word(cur, ("START",), f"#DISTANCE {prog}")
    _word(cur, ("CLEAR",), f"#DISTANCE {prog} START")
    return ContourStatement(ContourKind.DISTANCE_CLEAR, cur.line, hash_pos, number=number)


def _contour(cur: Cursor, hash_pos: int, number: int | None) -> ContourStatement:
    cur.skip_ws()
    m = IDENT.match(cur.up, cur.pos)
    if m is not None and m.group() != "LOOKAHEAD":  # #CONTOUR MODE ...: another command
        raise cur.error(NcErrorId.INSTRUCTION_NOT_SUPPORTED,
                        f"#CONTOUR {m.group()} is not supported yet", hash_pos)
    _word(cur, ("LOOKAHEAD",), "#CONTOUR")
    _word(cur, ("LOG",), "#CONTOUR LOOKAHEAD")
    cur.skip_ws()
    m = IDENT.match(cur.up, cur.pos)
    sub = m.group() if m is not None else ""
    stmt = ContourStatement(ContourKind.LOG_PARAM, cur.line, hash_pos, number=number)
    if sub in _LOG_WORDS:
        cur.pos += len(sub)
        stmt.kind = _LOG_WORDS[sub]
    elif sub != "PARAM" and cur.peek() != "[":
        raise _syntax(cur, "ON, OFF, CLEAR or [PARAM=..] expected after #CONTOUR LOOKAHEAD "
                           f"LOG, found {_found(cur)}")
    param_at = _skip(cur)
    stmt.param, stmt.param_pos = _param(cur)
    if stmt.kind == ContourKind.LOG_CLEAR and stmt.param is not None:
        raise _syntax(cur, "#CONTOUR LOOKAHEAD LOG CLEAR takes no PARAM", param_at)
    return stmt


def _param(cur: Cursor) -> tuple[Node | None, int]:
    """``[PARAM=<expr>]`` or ``PARAM=<expr>`` at the cursor: (expression, its position);
    (None, -1) when neither stands there."""
    cur.skip_ws()
    open_pos = cur.pos if cur.peek() == "[" else -1
    if open_pos >= 0:
        cur.pos += 1
        _word(cur, ("PARAM",), "'['")
    elif _match_word(cur, "PARAM") is None:
        return None, -1
    cur.skip_ws()
    if cur.peek() != "=":
        raise _syntax(cur, f"'=' expected after PARAM, found {_found(cur)}")
    cur.pos += 1
    expr_pos = _skip(cur)
    node = ExpressionParser(cur).parse()
    if open_pos >= 0:
        cur.skip_ws()
        if cur.peek() != "]":
            column = cur.line.locate(open_pos)[1]
            raise _syntax(cur, f"']' expected to close the '[' at column {column}, "
                               f"found {_found(cur)}")
        cur.pos += 1
    return node, expr_pos


def _word(cur: Cursor, expected: tuple[str, ...], after: str) -> str:
    """Consume one of the keywords ``expected`` (whole word) or raise a syntax error."""
    cur.skip_ws()
    for word in expected:
        if _match_word(cur, word) is not None:
            return word
    raise _syntax(cur, f"{' or '.join(expected)} expected after {after}, found {_found(cur)}")


def _match_word(cur: Cursor, word: str) -> str | None:
    cur.skip_ws()
    m = IDENT.match(cur.up, cur.pos)
    if m is None or m.group() != word:
        return None
    cur.pos = m.end()
    return word


def _skip(cur: Cursor) -> int:
    cur.skip_ws()
    return cur.pos


def _found(cur: Cursor) -> str:
    return f"'{cur.word_text()}'" if _skip(cur) < cur.end else "the end of the line"


def _syntax(cur: Cursor, message: str, pos: int | None = None) -> NcError:
    return cur.error(NcErrorId.CONTOUR_COMMAND_SYNTAX, message, pos)
