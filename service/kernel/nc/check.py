"""Decoding that goes on after an error: the decoder's part of the syntax check (FCT-C9).

With a ``SyntaxCheck`` the decoder reports each error (``SyntaxCheck.report``) and goes
on, with the response the ISG function description gives per error category:

==============================  ===========================================================
category                        response
==============================  ===========================================================
``resource`` (call depth, ...)  discard the NC line
``command`` (in a $ / # line)   discard the NC line (an opening $IF/$WHILE/$FOR/$SWITCH
                                whose expression fails skips its whole block, so its
                                closing line does not give a follow-up error)
``after_command``               use the command as far as it was understood (the text
                                after it is dropped)
``term`` (unknown word, bad     use what was understood of the line: the term is dropped
number, ...)                    and the rest of the line decoded
``assignment`` (bad left-hand   reposition after the assignment: it is dropped, the rest of
side)                           the line decoded
``combination``, ``limit``,     continue without repositioning: the offending word is
``value``, ``incomplete``       dropped and the block decoded again; when no single word is
                                at fault, the line is dropped
==============================  ===========================================================

A word dropped this way takes its effect with it (``G0 G1``: G0 stays; a bad F leaves
the feed unknown, so the check goes on as if F were programmed rather than report "no
feed" on every following line: ``CHECK_FEED_MM_MIN``). ``errors_per_block`` (P-CHAN-00020)
errors in one line (parse and execution errors together) skip the rest of that line, its
call and $GOTO included; the total limit (P-CHAN-00019) is the caller's: ``report``
raises ``CheckAborted`` to end decoding.

In check mode the hot path does not build Block objects: it yields ``PointBatch`` records
(line, motion kind, end point, arc centre) of up to ``BATCH_LINES`` plain lines, which
is what the check of software limits needs; every other line is decoded by the general
path, reported to ``SyntaxCheck.line`` and yields its Block as usual. While tool radius
compensation is active or the check steps line by line, every line takes the general
path.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from enum import IntEnum
from typing import NoReturn, Protocol, cast

from .blocks import MotionKind
from .errors import NcError, NcErrorId
from .expressions import ExpressionParser, VarRef
from .instructions import Instruction
from .lexer import Cursor
from .parser import ItemErrorHandler
from .source import LogicalLine, SourceText
from .statements import (
    Assign,
    AxisCommand,
    ContourStatement,
    Control,
    NcBlock,
    StmtKind,
    Word,
)

#: what a line parses to (``program.Statement``; that module imports this one)
Statement = NcBlock | Control | AxisCommand | ContourStatement | Instruction

BATCH_LINES = 2048  # plain lines per PointBatch (bounds the memory of one batch)
CHECK_FEED_MM_MIN = 1000.0  # the feed the check assumes after a missing or bad F


class ErrorCategory(IntEnum):
    """The rows of the ISG error table of the syntax check."""

    RESOURCE = 1  # e.g. stack overflow: discard the line
    COMMAND = 2  # error in a $ or # command: discard the line
    AFTER_COMMAND = 3  # unexpected character/term after a $ or # command: use the command
    TERM = 4  # unexpected or invalid character/term: use the rest of the line
    ASSIGNMENT = 5  # left-hand side of an assignment: reposition after the assignment
    COMBINATION = 6  # NC commands not permitted together: continue
    LIMIT = 7  # a limit over- or undershot: continue
    VALUE = 8  # programmed value impractical: continue
    INCOMPLETE = 9  # incomplete information: continue

    @property
    def label(self) -> str:
        """The lower-case name used in logs and JSON (``after_command``)."""
        return self.name.lower()


class CheckAborted(Exception):
    """Raised by ``SyntaxCheck.report`` to end decoding (error limit, RESET)."""


class ErrorReported(Exception):
    """Raised where the decoder uses a control statement whose line the check dropped
    (its error is reported already): it goes on as after a failing statement."""


class SyntaxCheck(Protocol):
    """What the decoder tells the syntax check; implemented by the kernel."""

    errors_per_block: int  # 0: no limit (P-CHAN-00020)
    line_by_line: bool  # every line through the general path and ``line`` (single step)

    def report(self, error: NcError, category: ErrorCategory) -> None:
        """An error the decoder goes on after; may block (interactive) or raise
        ``CheckAborted``."""

    def line(self, src: SourceText, index: int, after: int) -> None:
        """Lines ``index``..``after``-1 of ``src`` were decoded by the general path; may
        block (single step)."""


#: one moving line of a ``PointBatch``: (line index, motion, end point, arc centre or None)
BatchRecord = tuple[int, MotionKind, tuple[float, ...], tuple[float, float] | None]


@dataclass(slots=True)
class PointBatch:
    """Plain motion lines decoded by the hot path in check mode.

    ``records`` holds ``(line index, MotionKind, end point, centre)`` per line that
    moves; ``centre`` is the arc centre ``(p, q)`` in ``plane``, else None. The first
    record starts at ``start_mm``, each following one at the end of the one before.
    Lines ``first``..``stop``-1 of ``src`` were decoded.
    """

    src: SourceText
    first: int
    stop: int
    start_mm: tuple[float, ...]
    plane: tuple[int, int] | None
    records: list[BatchRecord] = field(default_factory=list)


# ---------------------------------------------------------------- categories

_RESOURCE = frozenset({
    NcErrorId.CALL_DEPTH_EXCEEDED, NcErrorId.EXPRESSION_TOO_COMPLEX, NcErrorId.ENDLESS_LOOP,
    NcErrorId.FILE_NOT_FOUND, NcErrorId.SUBPROGRAM_NOT_FOUND, NcErrorId.DUPLICATE_SUBPROGRAM,
    NcErrorId.INTERNAL_ERROR,
})
_COMBINATION = frozenset({
    NcErrorId.CONFLICTING_G_CODES, NcErrorId.CONFLICTING_M_CODES, NcErrorId.WORD_REPEATED,
    NcErrorId.BLOCK_NUMBER_TWICE, NcErrorId.ARC_CENTRE_AND_RADIUS,
    NcErrorId.ARC_WORDS_WITHOUT_ARC, NcErrorId.ARC_OFFSET_OUT_OF_PLANE,
    NcErrorId.HELIX_NOT_SUPPORTED, NcErrorId.AXIS_RELEASED, NcErrorId.AXIS_COMMAND_NOT_ALONE,
    NcErrorId.CONTOUR_CLEAR_WITH_COMPENSATION, NcErrorId.CONTOUR_CLEAR_IN_RT_LOOP,
    NcErrorId.SUBPROGRAM_END_IN_MAIN,
})
_LIMIT = frozenset({
    NcErrorId.VALUE_OUT_OF_RANGE, NcErrorId.VALUE_OUT_OF_TYPE_RANGE,
    NcErrorId.ARRAY_INDEX_OUT_OF_RANGE, NcErrorId.INVALID_SKIP_LEVEL,
})
_VALUE = frozenset({
    NcErrorId.INVALID_FEED, NcErrorId.INVALID_SPINDLE_SPEED, NcErrorId.INVALID_TOOL_NUMBER,
    NcErrorId.TOOL_NOT_IN_TABLE, NcErrorId.INVALID_M_CODE, NcErrorId.INVALID_DWELL,
    NcErrorId.DIVISION_BY_ZERO, NcErrorId.MATH_DOMAIN, NcErrorId.ARC_RADIUS_ZERO,
    NcErrorId.ARC_RADIUS_TOO_SMALL, NcErrorId.ARC_FULL_CIRCLE_WITH_R,
    NcErrorId.ARC_RADIUS_DIFFERENCE, NcErrorId.FOR_STEP_ZERO, NcErrorId.INVALID_AXIS_NUMBER,
    NcErrorId.INVALID_BLOCK_NUMBER, NcErrorId.AXIS_EXCHANGE_NOT_SUPPORTED,
    NcErrorId.TYPE_MISMATCH,
})
_INCOMPLETE = frozenset({
    NcErrorId.NO_FEED, NcErrorId.PLANE_AXIS_MISSING, NcErrorId.MISSING_PROGRAM_END,
    NcErrorId.SUBPROGRAM_END_MISSING, NcErrorId.BLOCK_NOT_CLOSED, NcErrorId.VAR_BLOCK_NOT_CLOSED,
    NcErrorId.COMMENT_BLOCK_NOT_CLOSED, NcErrorId.STRING_NOT_CLOSED,
    NcErrorId.UNDECLARED_VARIABLE, NcErrorId.UNKNOWN_VARIABLE, NcErrorId.LABEL_NOT_FOUND,
})

# the category of an error id found in no command and no assignment target
_CATEGORY_OF_ID: dict[int, ErrorCategory] = {
    int(err_id): category
    for ids, category in ((_COMBINATION, ErrorCategory.COMBINATION),
                          (_LIMIT, ErrorCategory.LIMIT), (_VALUE, ErrorCategory.VALUE),
                          (_INCOMPLETE, ErrorCategory.INCOMPLETE))
    for err_id in ids
}

# the $ or # that starts the command of a line (after an N number and a label). Every
# run is possessive: blanks next to blanks ("N  :  ") must not be split up in all ways
# when there is no command, which made a line of thousands of blanks take minutes.
_COMMAND_START = re.compile(
    r"[ \t]*+(?:N[ \t]*+[0-9]*+[ \t]*+:?[ \t]*+)?(?:\[[^\]]*+\][ \t]*+)?([$#])")
# a run of characters that opens neither brackets nor a string, up to a blank
_PLAIN_RUN = re.compile(r'[^ \t\["]*')
# "V.x.name[...] =" (not "==") at a position: the target of an assignment
_ASSIGN_TARGET = re.compile(r"V\.[A-Z]+\.[A-Z_][A-Z0-9_]*(?:\[[^\]=]*\])*[ \t]*=(?!=)")


def command_position(line: LogicalLine) -> int:
    """Position of the ``$``/``#`` of a command line ($GOTO is an NC word), else -1."""
    m = _COMMAND_START.match(line.upper)
    if m is None or line.upper.startswith("$GOTO", m.start(1)):
        return -1
    return m.start(1)


def categorize(error: NcError, line: LogicalLine | None,
               command_at: int | None = None) -> ErrorCategory:
    """The category of ``error`` found in ``line`` (None: not in one line);
    ``command_at``: ``command_position(line)`` when the caller knows it already."""
    err_id = error.id
    if err_id in _RESOURCE:
        return ErrorCategory.RESOURCE
    if err_id == NcErrorId.COMMENT_END_WITHOUT_BEGIN:  # a # command, found before parsing
        return ErrorCategory.COMMAND
    if line is not None and error.pos >= 0:
        if _ASSIGN_TARGET.match(line.upper, error.pos):
            return ErrorCategory.ASSIGNMENT
        if (command_position(line) if command_at is None else command_at) >= 0:
            return ErrorCategory.COMMAND
    return _CATEGORY_OF_ID.get(err_id, ErrorCategory.TERM)


# ---------------------------------------------------------------- repositioning

class RepositionedLine(LogicalLine):
    """A line with parts blanked after errors; ``errors``: how many were reported in it
    (they count towards ``errors_per_block`` when the block is executed)."""

    __slots__ = ("errors",)

    def __init__(self, line: LogicalLine, text: str, errors: int = 0) -> None:
        super().__init__(line.file, text, line.segments, line.offset)
        self.errors = errors

    @classmethod
    def counted(cls, line: LogicalLine, errors: int) -> RepositionedLine:
        """``line`` itself (its text not copied, not upper-cased again) with ``errors``."""
        if type(line) is cls:
            line.errors = errors
            return line
        new = cls.__new__(cls)
        for name in LogicalLine.__slots__:
            setattr(new, name, getattr(line, name))
        new.errors = errors
        return new


def blanked(line: LogicalLine, start: int, stop: int) -> RepositionedLine:
    """``line`` with ``[start, stop)`` replaced by blanks (columns stay as they were)."""
    text = line.text[:start] + " " * (stop - start) + line.text[stop:]
    return RepositionedLine(line, text, getattr(line, "errors", 0))


def term_start(text: str, pos: int, origin: int = 0) -> int:
    """Start of the term that holds ``pos``: ``pos`` itself, or when ``pos`` is inside
    brackets or a string, the start of the word whose ``[`` or ``"`` opened them (an
    error inside ``X[...]`` drops all of ``X[...]``, not the part after the error).
    ``origin``: a position outside any brackets or string at or before ``pos`` (the
    start of the item being parsed), where the scan begins."""
    run = _PLAIN_RUN.match(text, origin, pos)
    assert run is not None  # the pattern matches the empty string too
    if run.end() >= pos:  # no bracket or string before
        return pos
    depth = 0
    quoted = False
    opened = pos
    for k in range(origin, min(pos, len(text))):
        c = text[k]
        if c == '"':
            if not quoted and depth == 0:
                opened = k
            quoted = not quoted
        elif not quoted:
            if c == "[":
                if depth == 0:
                    opened = k
                depth += 1
            elif c == "]":
                depth = max(depth - 1, 0)
    if depth == 0 and not quoted:
        return pos
    while opened > 0 and (text[opened - 1].isalpha() or text[opened - 1] in "._+-"):
        opened -= 1
    return opened


def term_end(text: str, pos: int) -> int:
    """End of the term at ``pos``: the next blank outside brackets and strings."""
    n = len(text)
    k = pos + 1 if pos < n and text[pos] in " \t" else pos
    run = _PLAIN_RUN.match(text, k)
    assert run is not None  # the pattern matches the empty string too
    k = run.end()
    if k >= n or text[k] in " \t":  # no bracket, no string: the next blank
        return k
    depth = 0
    quoted = False
    k = pos
    n = len(text)
    while k < n:
        c = text[k]
        if c == '"':
            quoted = not quoted
        elif not quoted:
            if c == "[":
                depth += 1
            elif c == "]":
                depth = max(depth - 1, 0)
            elif c in " \t" and depth == 0 and k > pos:
                break
        k += 1
    return k


def assignment_end(line: LogicalLine, pos: int) -> int:
    """End of the assignment whose target starts at ``pos``: after its right-hand
    expression, or the end of the line when that cannot be parsed either."""
    m = _ASSIGN_TARGET.match(line.upper, pos)
    if m is None:
        return len(line.text)
    cur = Cursor(line, m.end())
    try:
        ExpressionParser(cur).parse()
    except NcError:
        return len(line.text)
    return cur.pos


def without_error(line: LogicalLine, error: NcError, category: ErrorCategory
                  ) -> RepositionedLine | None:
    """The line to parse again after ``error``, or None to drop the line."""
    pos = error.pos
    if pos < 0 or pos > len(line.text) or category in (ErrorCategory.RESOURCE,
                                                        ErrorCategory.COMMAND):
        return None
    if pos < len(line.text):
        if category == ErrorCategory.ASSIGNMENT:
            return blanked(line, pos, assignment_end(line, pos))
        if category == ErrorCategory.AFTER_COMMAND:
            return blanked(line, pos, len(line.text))
    start = term_start(line.text, pos)  # at the end: an unclosed bracket or string
    if start >= len(line.text):
        return None
    return blanked(line, start, term_end(line.text, start))


def item_at(line: LogicalLine, items: list[Word | Assign], pos: int) -> int | None:
    """Index of the item (word or assignment) of an NC block whose text holds ``pos``
    (an error in ``X[1/0]`` or ``V.L.A = 1/0`` is that item's), or None."""
    found = None
    for k, item in enumerate(items):
        if item.pos <= pos and (found is None or item.pos > items[found].pos):
            found = k
    if found is None:
        return None
    start = items[found].pos
    if type(items[found]) is Assign:
        end = assignment_end(line, start)
    else:
        end = term_end(line.text, start)
    return found if pos < end else None


def holds_error(line: LogicalLine, items: list[Word | Assign], k: int, pos: int) -> bool:
    """True when ``item_at(line, items, pos)`` is ``k``, found without scanning the
    other items (the items of a block stand in the order of their text)."""
    item = items[k]
    if item.pos > pos or (k + 1 < len(items) and items[k + 1].pos <= pos):
        return False
    if type(item) is Assign:
        return pos < assignment_end(line, item.pos)
    return pos < term_end(line.text, item.pos)


class LineParse(Protocol):
    """``LineParser.parse``: the statement of a line; ``on_error`` handles the errors
    in the items of an NC block (the check's one pass)."""

    def __call__(self, line: LogicalLine, on_error: ItemErrorHandler | None = None, /
                 ) -> Statement: ...


def after_command(line: LogicalLine, error: NcError, parse: LineParse) -> Statement | None:
    """For an error in a command line: the command as understood before ``error``
    (``parse`` of the line cut there) when that is a command, else None."""
    start = command_position(line)
    if start < 0 or error.pos <= start + 1 or error.pos >= len(line.text):
        return None
    try:
        stmt = parse(blanked(line, error.pos, len(line.text)))
    except NcError:
        return None
    return None if isinstance(stmt, NcBlock) else stmt


class _Dropped:
    """The expressions (and the ``$FOR`` variable) of a control statement whose line
    was dropped: evaluating them raises ``ErrorReported``."""

    __slots__ = ()

    def __call__(self, env: object) -> NoReturn:
        raise ErrorReported

    def assign(self, env: object, value: object) -> NoReturn:
        raise ErrorReported


_DROPPED = _Dropped()
# the keyword of a control statement that has an expression
_CONTROL_WITH_EXPRESSION = re.compile(
    r"\$(IF|ELSEIF|WHILE|FOR|SWITCH|CASE|UNTIL)\b|#[ \t]*RT[ \t]+WHILE\b")


def dropped_control(line: LogicalLine, errors: int) -> Control | None:
    """For a dropped line of a control statement with an expression ($IF, $ELSEIF,
    $WHILE, $FOR, $SWITCH, $CASE, $UNTIL, #RT WHILE): a statement of that kind whose
    expressions raise ``ErrorReported``, so the control flow keeps its structure (a
    dropped $IF skips its block, a dropped $CASE never matches, ...); else None.
    ``errors``: the errors reported in the line."""
    start = command_position(line)
    if start < 0:
        return None
    m = _CONTROL_WITH_EXPRESSION.match(line.upper, start)
    if m is None:
        return None
    if m.group(1) is None:
        kind = StmtKind.RT_WHILE
    elif m.group(1) == "IF" and "$GOTO" in line.upper[m.end():]:
        kind = StmtKind.IF_GOTO
    else:
        kind = StmtKind[m.group(1)]
    line = RepositionedLine(line, line.text, errors)
    # the $FOR variable: only its ``assign`` is used, which _Dropped has
    target = cast(VarRef, _DROPPED)
    return Control(kind, line, start, expr=_DROPPED, target=target, end=_DROPPED,
                   step=_DROPPED, values=(_DROPPED,))


EXACT_REPOSITIONS = 16  # per line: errors inside a term repositioned by a blanked copy


class _LineDropped(Exception):
    """Raised by ``_ItemErrors`` to drop the rest of the line."""


class _ItemErrors:
    """The parser's handler of an error in an item of an NC block (``ItemErrorHandler``):
    reports it and says where parsing goes on, in the same pass over the line.

    The result is the one of blanking the term and parsing the line again (the
    reference): after an error at the item's start the parser goes on after the term;
    after one inside the item (``V.P.A = 1 +* 2``) it parses the item again on a copy
    of the line with the term blanked. Such copies cost the line's length, so after
    ``EXACT_REPOSITIONS`` of them in one line the whole item is dropped instead: the
    check of a line stays linear in its length whatever it holds."""

    __slots__ = ("line", "check", "count", "copies", "_command_at")

    def __init__(self, line: LogicalLine, check: SyntaxCheck, count: int) -> None:
        self.line = line
        self.check = check
        self.count = count
        self.copies = 0
        self._command_at: int | None = None

    def __call__(self, error: NcError, item: int) -> int | LogicalLine:
        line = self.line
        command_at = self._command_at
        if command_at is None:
            command_at = self._command_at = command_position(line)
        if command_at >= 0:  # not an NC block after all: the general way
            raise error
        category = categorize(error, line, command_at)
        check = self.check
        check.report(error, category)
        self.count += 1
        limit = check.errors_per_block
        text = line.text
        pos = error.pos
        if (limit and self.count >= limit) or pos < 0 or pos > len(text) or category in (
                ErrorCategory.RESOURCE, ErrorCategory.COMMAND):
            raise _LineDropped
        if category == ErrorCategory.ASSIGNMENT and pos < len(text):
            start, stop = pos, assignment_end(line, pos)
        else:
            start = pos if pos == item else term_start(text, pos, item)
            if start >= len(text):
                raise _LineDropped
            stop = term_end(text, start)
        if stop <= item:  # no progress: nothing left to drop
            raise _LineDropped
        if start > item and self.copies < EXACT_REPOSITIONS:
            self.copies += 1
            self.line = blanked(line, start, stop)
            return self.line
        return stop


def parse_checked(parse: LineParse, line: LogicalLine, check: SyntaxCheck
                  ) -> Statement | None:
    """Parse ``line``, reporting each error and repositioning after it; the statement
    of what was understood, or None when the line is dropped (a control statement
    with an expression stays as ``dropped_control``).

    Errors in the items of an NC block are handled during the one pass of the parser
    (``_ItemErrors``); an error elsewhere (block number, label, a ``$``/``#`` command)
    blanks the term and parses the line again, which happens a bounded number of
    times per line."""
    original = line
    count = 0
    while True:
        handler = _ItemErrors(line, check, count)
        try:
            stmt = parse(line, handler)
            if handler.count > count:  # errors in its items: the block counts them
                stmt.line = RepositionedLine.counted(stmt.line, handler.count)
            return stmt
        except _LineDropped:
            return dropped_control(original, handler.count)
        except NcError as error:
            count = handler.count
            line = handler.line
            command = after_command(line, error, parse)
            category = ErrorCategory.AFTER_COMMAND if command is not None else \
                categorize(error, line)
            check.report(error, category)
            count += 1
            if check.errors_per_block and count >= check.errors_per_block:
                return dropped_control(original, count)
            if command is not None:
                return command
            again = without_error(line, error, category)
            if again is None or again.text == line.text:
                return dropped_control(original, count)
            again.errors = count
            line = again


__all__ = [
    "BATCH_LINES", "CHECK_FEED_MM_MIN", "CheckAborted", "ErrorCategory", "ErrorReported",
    "PointBatch", "SyntaxCheck", "categorize", "command_position", "holds_error", "item_at",
    "parse_checked",
]

