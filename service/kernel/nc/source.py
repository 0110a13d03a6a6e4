"""Physical lines to logical lines, keeping file, line, column and byte offset.

An NC file is a sequence of physical lines (``SourceText``, ``text_pages``: held whole,
or read from its file page by page). The decoder reads it one *logical line* at a time
(``read_logical``):

* ``;`` starts a comment to the end of the line; ``( ... )`` is a comment inside the
  line (an unclosed ``(`` runs to the end of the line). Comment characters inside
  ``"strings"`` are text. Comments are blanked with spaces, so columns stay exact.
* ``#COMMENT BEGIN`` ... ``#COMMENT END`` (each on a line of its own) is a block comment.
* ``/`` or ``/n`` (n = 1..10) at the start of a line: skip line of level n (``/`` is
  level 1). It is skipped when bit n-1 of ``skip_levels`` is set, else decoded as if the
  prefix were blank.
* A line whose code ends with ``\\`` continues on the next line. Blank and comment-only
  lines inside a continuation are skipped and do not end it (ISG programs comment out
  parameters of a long cycle call this way).

A ``LogicalLine`` keeps, for every part of its text, the physical line and column it
came from, so an error in the third continuation line points at that line.
"""

from __future__ import annotations

import re

from .errors import NcError, NcErrorId
from .text_pages import NcText, SourceText, comment_directive

__all__ = ["LogicalLine", "NcText", "SourceText", "comment_directive", "join_lines",
           "read_logical", "skip_comment_block", "strip_comments"]
_SKIP_PREFIX = re.compile(r"[ \t]*/([0-9]*)")
_MAX_SKIP_LEVEL = 10


class LogicalLine:
    """The code of one logical line (comments blanked) and where each part came from.

    ``segments`` holds ``(start, line_index, column0)``: the text from ``start`` on came
    from physical line ``line_index`` (0-based) beginning at 0-based column ``column0``.
    """

    __slots__ = ("file", "text", "upper", "segments", "index", "offset")

    def __init__(
        self, file: str, text: str, segments: tuple[tuple[int, int, int], ...], offset: int
    ) -> None:
        self.file = file
        self.text = text
        self.upper = _upper(text)
        self.segments = segments
        self.index = segments[0][1]  # physical index of the first line
        self.offset = offset  # byte offset of the first physical line

    def locate(self, pos: int) -> tuple[int, int]:
        """1-based (line, column) of the character at ``pos`` of ``text``."""
        found = self.segments[0]
        for seg in self.segments:
            if seg[0] > pos:
                break
            found = seg
        start, line_index, col0 = found
        return line_index + 1, col0 + (pos - start) + 1

    def error(self, err_id: NcErrorId, message: str, pos: int) -> NcError:
        """An NcError pointing at ``pos`` of this line."""
        line, column = self.locate(pos)
        error = NcError(err_id, self.file, line, column, message)
        error.pos = pos
        return error


def _upper(text: str) -> str:
    """Upper case with the same length (some characters grow when upper-cased: ß)."""
    up = text.upper()
    if len(up) == len(text):
        return up
    return "".join(c if len(c.upper()) != 1 else c.upper() for c in text)


def strip_comments(line: str) -> str:
    """The code of one physical line: ``( )`` comments blanked, ``;`` comment cut off."""
    if "(" not in line and '"' not in line:
        return line.partition(";")[0]
    out = []
    in_string = False
    in_comment = False
    for c in line:
        if in_comment:
            out.append(" ")
            if c == ")":
                in_comment = False
        elif in_string:
            out.append(c)
            if c == '"':
                in_string = False
        elif c == '"':
            in_string = True
            out.append(c)
        elif c == "(":
            in_comment = True
            out.append(" ")
        elif c == ";":
            break
        else:
            out.append(c)
    return "".join(out)


def skip_comment_block(src: SourceText, index: int, end: int) -> int:
    """Index after the ``#COMMENT END`` that closes the ``#COMMENT BEGIN`` at ``index``."""
    line = src.line
    for k in range(index + 1, end):
        if comment_directive(line(k)) == "END":
            return k + 1
    first = line(index)
    col = len(first) - len(first.lstrip()) + 1
    raise NcError(
        NcErrorId.COMMENT_BLOCK_NOT_CLOSED, src.name, index + 1, col,
        "#COMMENT BEGIN without #COMMENT END",
    )


def read_logical(
    src: SourceText, index: int, end: int, skip_levels: int
) -> tuple[LogicalLine | None, int]:
    """The logical line starting at physical line ``index`` and the index after it.

    Returns ``(None, next)`` for a line without code: blank, comment only, a whole
    ``#COMMENT`` block, or a skipped ``/`` line.
    """
    raw = src.line(index)
    directive = comment_directive(raw)
    if directive == "BEGIN":
        return None, skip_comment_block(src, index, end)
    if directive == "END":
        col = len(raw) - len(raw.lstrip()) + 1
        raise NcError(
            NcErrorId.COMMENT_END_WITHOUT_BEGIN, src.name, index + 1, col,
            "#COMMENT END without #COMMENT BEGIN",
        )
    code = strip_comments(raw)
    m = _SKIP_PREFIX.match(code)
    if m is not None:
        digits = m.group(1)
        level = int(digits) if digits else 1
        if not 1 <= level <= _MAX_SKIP_LEVEL:
            raise NcError(
                NcErrorId.INVALID_SKIP_LEVEL, src.name, index + 1, m.start(1) + 1,
                f"skip level /{digits} is outside 1..{_MAX_SKIP_LEVEL}",
            )
        if skip_levels >> (level - 1) & 1:
            return None, index + 1
        code = " " * m.end() + code[m.end():]  # keep the columns of the rest
    stripped = code.rstrip()
    if not stripped:
        return None, index + 1
    if not stripped.endswith("\\"):
        return LogicalLine(src.name, code, ((0, index, 0),), src.offset(index)), index + 1
    # continuation: join the following lines; blank and comment-only lines are skipped
    parts = [stripped[:-1] + " "]
    segments = [(0, index, 0)]
    length = len(parts[0])
    k = index + 1
    while k < end:
        more = strip_comments(src.line(k))
        more_stripped = more.rstrip()
        k += 1
        if not more_stripped:
            continue
        segments.append((length, k - 1, 0))
        if more_stripped.endswith("\\"):
            part = more_stripped[:-1] + " "
            parts.append(part)
            length += len(part)
            continue
        parts.append(more)
        break
    return (
        LogicalLine(src.name, "".join(parts), tuple(segments), src.offset(index)),
        k,
    )


def join_lines(first: LogicalLine, more: LogicalLine) -> LogicalLine:
    """One logical line made of two (a ``#VAR`` initializer list spanning lines)."""
    shift = len(first.text) + 1
    segments = first.segments + tuple((s + shift, i, c) for s, i, c in more.segments)
    return LogicalLine(first.file, first.text + " " + more.text, segments, first.offset)
