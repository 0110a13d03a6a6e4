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
(``RtLoopMarkers``): RT_PASS before each pass, RT_END after the last one. Only the
outermost such loop is tracked; a loop entered while the area is not open never gets
markers, so a program without the contour look-ahead gives the blocks it always gave.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from .blocks import (
    Block, Compensation, ContourCommand, ContourKind, LogArea, StopKind, next_log_area,
)
from .construct import make_block, make_source
from .errors import NcError, NcErrorId
from .evaluation import evaluate_number
from .expressions import ExpressionParser, Node
from .lexer import IDENT, Cursor
from .source import LogicalLine
from .statements import ContourStatement, StmtKind

if TYPE_CHECKING:  # frames imports the parser, which imports this module
    from .frames import ControlEntry, Frame

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
NOT_ENABLED = ("#CONTOUR LOOKAHEAD needs the contour look-ahead function: add "
               "FCT_CONTOUR_LAH to the channel's interpolator_function (P-CHAN-00650)")
CLEAR_IN_RT_LOOP = "#CONTOUR LOOKAHEAD LOG CLEAR is not allowed inside #RT WHILE"
CLEAR_WITH_COMPENSATION = ("#CONTOUR LOOKAHEAD LOG CLEAR is not allowed while tool radius "
                           "compensation (G41/G42) is active: program it after G40")


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
        cur.pos = m.end()
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


# ------------------------------------------------------------------ execution


def execute_contour(stmt: ContourStatement, decoder: Any) -> Block:
    """Run a contour command: its Block; LOG commands move the log area.

    ``decoder`` is the running Decoder (its variables, ``contour_lookahead``, frames,
    modal state). Everything is checked before the modal state changes.
    """
    kind = stmt.kind
    if kind != ContourKind.DISTANCE_CLEAR and not decoder.contour_lookahead:
        raise stmt.line.error(NcErrorId.CONTOUR_LOOKAHEAD_NOT_ENABLED, NOT_ENABLED, stmt.pos)
    if kind == ContourKind.LOG_CLEAR and inside_rt_loop(decoder.frames):
        raise stmt.line.error(NcErrorId.CONTOUR_CLEAR_IN_RT_LOOP, CLEAR_IN_RT_LOOP, stmt.pos)
    if kind == ContourKind.LOG_CLEAR and decoder.modal.compensation != Compensation.OFF:
        # Flush and wait needs the path to end here; tool radius compensation cannot end
        # an offset element before it knows the next one (it would deselect and jump).
        raise stmt.line.error(NcErrorId.CONTOUR_CLEAR_WITH_COMPENSATION,
                              CLEAR_WITH_COMPENSATION, stmt.pos)
    param = None
    if stmt.param is not None:
        param = evaluate_number(stmt.param, decoder, stmt.line, stmt.param_pos)
    modal = decoder.modal
    modal.contour_log_area = next_log_area(modal.contour_log_area, kind)
    return contour_block(stmt.line, stmt.pos, stmt.number, decoder.manual,
                         ContourCommand(kind, param))


def inside_rt_loop(frames: list[Frame]) -> bool:
    """True when a ``#RT WHILE`` is open in any frame (a subprogram called from inside
    a real-time loop runs inside it too)."""
    return any(entry.kind == StmtKind.RT_WHILE for frame in frames for entry in frame.control)


def contour_block(line: LogicalLine, pos: int, number: int | None, manual: bool,
                  command: ContourCommand) -> Block:
    """A Block without motion carrying ``command``, at ``pos`` (the '#') of ``line``."""
    line_no, column = line.locate(pos)
    return make_block(make_source(line.file, line_no, column, line.offset), number, None,
                      0.0, StopKind.NONE, (), None, None, manual, None, command)


# ------------------------------------------------------------------ real-time loop markers


@dataclass(slots=True)
class _Tracked:
    """The real-time loop that gets markers: where it runs and how far it is."""

    frame: Frame
    entry: ControlEntry  # its open control entry (a new one each pass)
    serial: int
    rt_pass: int


class RtLoopMarkers:
    """Marker Blocks at the passes of the real-time loop entered in an open marked area.

    ``ControlFlow`` reports every test of a ``#RT WHILE`` condition (``tested``), every
    ``#RT ENDWHILE`` (``closed``: the next test of that loop is a re-test) and the
    entries a ``$BREAK`` leaves (``broken``). A loop is tracked when it is entered (first
    test, not a re-test) with a true condition while ``contour_log_area`` is OPEN and no
    other loop is tracked: RT_PASS 1. Each true re-test gives RT_PASS n+1, a false one
    RT_END. A ``$BREAK`` out of the tracked loop gives RT_END. A ``$GOTO`` (or an M17)
    out of it gives no marker: the loop simply stops being tracked.
    """

    def __init__(self, decoder: Any) -> None:
        self.decoder = decoder
        self.serial = 0  # serial number of the last tracked loop (per decoder)
        self.tracked: _Tracked | None = None
        self._closed: tuple[Frame, ControlEntry] | None = None  # the last #RT ENDWHILE

    def closed(self, frame: Frame, entry: ControlEntry) -> None:
        """``#RT ENDWHILE`` closed ``entry``: its loop tests its condition next."""
        self._closed = (frame, entry)

    def tested(self, frame: Frame, stmt: Any, index: int,
               entry: ControlEntry | None) -> Block | None:
        """The ``#RT WHILE`` ``stmt`` at line ``index`` was tested: ``entry`` is its new
        control entry (None: the condition was false). The marker, if any."""
        closed, self._closed = self._closed, None
        retest = closed is not None and closed[0] is frame and closed[1].index == index
        tracked = self.tracked
        if retest:
            if tracked is None or tracked.entry is not closed[1]:
                return None  # an untracked loop (or one nested in the tracked one)
            if entry is None:
                self.tracked = None
                return self._marker(stmt, ContourCommand(ContourKind.RT_END, loop=tracked.serial))
            tracked.entry = entry
            tracked.rt_pass += 1
            return self._pass(stmt, tracked)
        if (entry is None or self.decoder.modal.contour_log_area != LogArea.OPEN
                or self._alive()):
            return None
        self.serial += 1
        self.tracked = _Tracked(frame, entry, self.serial, 1)
        return self._pass(stmt, self.tracked)

    def broken(self, frame: Frame, left: list[ControlEntry]) -> Block | None:
        """A ``$BREAK`` left the control entries ``left`` of ``frame``: RT_END when the
        tracked loop is among them."""
        tracked = self.tracked
        if tracked is None or tracked.frame is not frame:
            return None
        if not any(e is tracked.entry for e in left):
            return None
        self.tracked = None
        return self._marker(tracked.entry.stmt,
                            ContourCommand(ContourKind.RT_END, loop=tracked.serial))

    def _alive(self) -> bool:
        """True while the tracked loop is open; forgets it once a $GOTO or a subprogram
        end has left it."""
        tracked = self.tracked
        if tracked is None:
            return False
        alive = (any(f is tracked.frame for f in self.decoder.frames)
                 and any(e is tracked.entry for e in tracked.frame.control))
        if not alive:
            self.tracked = None
        return alive

    def _pass(self, stmt: Any, tracked: _Tracked) -> Block:
        return self._marker(stmt, ContourCommand(ContourKind.RT_PASS, loop=tracked.serial,
                                                 rt_pass=tracked.rt_pass))

    def _marker(self, stmt: Any, command: ContourCommand) -> Block:
        return contour_block(stmt.line, stmt.pos, stmt.number, self.decoder.manual, command)
