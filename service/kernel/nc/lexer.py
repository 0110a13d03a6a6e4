"""A cursor over one logical line: the character-level scanning the parsers share.

NC syntax is context dependent (``X10`` is a word, ``XV.L.A`` a word whose value is a
variable, ``LL UP1`` a call, ``$IF`` a control statement), so there is no separate token
stream: the parsers ask the cursor for the next number, identifier, variable name or
operator at the current position. Matching works on the upper-cased text (NC is case
insensitive); strings and file names are taken from the original text.
"""

from __future__ import annotations

import re

from .errors import NcError, NcErrorId
from .source import LogicalLine

_WS = re.compile(r"[ \t\f\v]*")
_BLANKS = " \t\f\v"
# unsigned: in an expression a sign is an operator
NUMBER = re.compile(r"(?:[0-9]+\.?[0-9]*|\.[0-9]+)")
SIGNED_NUMBER = re.compile(r"[-+]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)")
IDENT = re.compile(r"[A-Z_][A-Z0-9_]*")
VARIABLE = re.compile(r"V\.([A-Z]+)\.([A-Z_][A-Z0-9_]*)")
_NAME = re.compile(r"[^ \t\f\v]+")  # a file or subprogram name: anything up to a blank
# the start of a word shown in a message: never more than 25 characters are looked at,
# so an error in a word of a megabyte costs no more than one in ``X1``
_SHOWN = re.compile(r"[^ \t\f\v]{1,25}")
_SHOWN_MAX = 24


class Cursor:
    """Position in a logical line plus scanning helpers."""

    __slots__ = ("line", "text", "up", "pos", "end")

    def __init__(self, line: LogicalLine, pos: int = 0) -> None:
        self.line = line
        self.text = line.text
        self.up = line.upper
        self.pos = pos
        self.end = len(self.text)

    def skip_ws(self) -> None:
        """Move over blanks."""
        pos = self.pos
        if pos < self.end and self.up[pos] not in _BLANKS:  # most often: no blank here
            return
        m = _WS.match(self.up, pos)
        assert m is not None  # the pattern matches the empty string too
        self.pos = m.end()

    def at_end(self) -> bool:
        """True when only blanks are left."""
        self.skip_ws()
        return self.pos >= self.end

    def peek(self, offset: int = 0) -> str:
        """The upper-case character at pos+offset ('' past the end)."""
        k = self.pos + offset
        return self.up[k] if k < self.end else ""

    def startswith(self, s: str) -> bool:
        """True when the upper-case text continues with ``s``."""
        return self.up.startswith(s, self.pos)

    def match(self, pattern: re.Pattern[str]) -> re.Match[str] | None:
        """Match ``pattern`` on the upper-case text at pos; advance past it on success."""
        m = pattern.match(self.up, self.pos)
        if m is not None:
            self.pos = m.end()
        return m

    def name(self) -> str:
        """The original text of the next blank-delimited name ('' when none)."""
        self.skip_ws()
        m = _NAME.match(self.text, self.pos)
        if m is None:
            return ""
        self.pos = m.end()
        return m.group()

    def word_text(self, pos: int | None = None) -> str:
        """The blank-delimited text at ``pos`` (for messages), shortened when long."""
        m = _SHOWN.match(self.text, self.pos if pos is None else pos)
        text = m.group() if m else ""
        return text if len(text) <= _SHOWN_MAX else text[:_SHOWN_MAX - 3] + "..."

    def error(self, err_id: NcErrorId, message: str, pos: int | None = None) -> NcError:
        """An NcError at ``pos`` (default: the current position)."""
        return self.line.error(err_id, message, self.pos if pos is None else pos)

    def unexpected(self, context: str) -> NcError:
        """An error for whatever stands at the current position."""
        self.skip_ws()
        if self.pos >= self.end:
            return self.error(NcErrorId.EXPRESSION_SYNTAX, f"unexpected end of line {context}")
        return self.error(
            NcErrorId.UNKNOWN_WORD, f"unexpected '{self.word_text()}' {context}"
        )
