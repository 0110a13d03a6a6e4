"""The structure of one NC file: sections, labels, control-block matching, parse cache.

A file is cut into sections at its ``%`` header lines (header lines inside
``#COMMENT`` blocks do not count):

* ``%L name`` starts a local subprogram (called with ``LL name``); it ends at the next
  ``%`` line or the end of the file, where it returns even without M17.
* ``%name`` (or a bare ``%``) starts the main program, which ends at the next ``%``
  line or the end of the file. A file without such a header is a main program from its
  first line to its first ``%L`` (local subprograms may stand before or after it).

Labels (``Nnn:`` and ``[NAME]`` at the start of a line) are indexed per section when
the first ``$GOTO`` of that section needs them. ``$GOTO`` searches forward from the
jump to the end of the section, then from the section start (ISG searches both ways;
with a label defined twice, the next one after the jump wins).

The lines come from a ``SourceText`` (``text_pages``): a stored program is read from its
file page by page, so nothing here holds the whole text; the label index and the
structures keep line indices only.

Everything is computed lazily and cached: the statement of a line is parsed when the
line is first reached, the matching ``$ENDIF`` of an ``$IF`` is searched when needed.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from enum import IntEnum

from .check import SyntaxCheck, categorize, parse_checked
from .errors import NcError, NcErrorId
from .instructions import Instruction
from .parser import LineParser
from .source import (
    LogicalLine,
    NcText,
    SourceText,
    comment_directive,
    read_logical,
    strip_comments,
)
from .statements import (
    CLOSER_OF,
    OPENERS,
    SPELLING,
    AxisCommand,
    ContourStatement,
    Control,
    Declaration,
    NcBlock,
    StmtKind,
)

# what a parsed line is
Statement = NcBlock | Control | AxisCommand | ContourStatement | Instruction

# parsed lines kept for loops and repeated calls; a long straight program does not
# keep all of its lines parsed in memory (the cache starts over when full)
CACHE_LINES = 20_000
_LOCAL_HEADER = re.compile(r"[ \t]*%[ \t]*L[ \t]+(\S+)", re.I)
_MAIN_HEADER = re.compile(r"[ \t]*%[ \t]*(\S*)")
# the statement keyword of a line, without parsing it: $WORD or #RT WHILE/ENDWHILE
# (possessive runs: blanks next to blanks must not be split up in every way on a miss)
_KEYWORD_SCAN = re.compile(
    r"[ \t]*+(?:N[ \t]*+[0-9]++[ \t]*+:?[ \t]*+)?(?:\[[ \t]*+[A-Z0-9_]++[ \t]*+\][ \t]*+)?"
    r"(?:\$([A-Z]+)|#[ \t]*+RT[ \t]++(WHILE|ENDWHILE)\b)"
)
_LABEL_SCAN = re.compile(
    r"[ \t]*(?:N[ \t]*([0-9]+)[ \t]*(:)?[ \t]*)?(?:\[[ \t]*([A-Z0-9_]+)[ \t]*\])?"
)
_KEYWORDS = {
    "IF": StmtKind.IF, "ELSEIF": StmtKind.ELSEIF, "ELSE": StmtKind.ELSE,
    "ENDIF": StmtKind.ENDIF, "WHILE": StmtKind.WHILE, "ENDWHILE": StmtKind.ENDWHILE,
    "FOR": StmtKind.FOR, "ENDFOR": StmtKind.ENDFOR, "REPEAT": StmtKind.REPEAT,
    "UNTIL": StmtKind.UNTIL, "SWITCH": StmtKind.SWITCH, "CASE": StmtKind.CASE,
    "DEFAULT": StmtKind.DEFAULT, "ENDSWITCH": StmtKind.ENDSWITCH,
}
# parts of a structure that the opener needs to know about
_PARTS = {StmtKind.IF: (StmtKind.ELSEIF, StmtKind.ELSE),
          StmtKind.SWITCH: (StmtKind.CASE, StmtKind.DEFAULT)}
# a part of a block scans like the block's opener (from an $ELSE to its $ENDIF)
_OPENER_OF = {StmtKind.ELSEIF: StmtKind.IF, StmtKind.ELSE: StmtKind.IF,
              StmtKind.CASE: StmtKind.SWITCH, StmtKind.DEFAULT: StmtKind.SWITCH}
# errors for a closer that does not match
_CLOSER_ERROR = {
    StmtKind.ENDIF: NcErrorId.ENDIF_WITHOUT_IF,
    StmtKind.ENDSWITCH: NcErrorId.SWITCH_PART_WITHOUT_SWITCH,
}


class SectionKind(IntEnum):
    """Kind of a section of a file."""

    MAIN = 0  # the main program (of a main file or of a file subprogram)
    LOCAL = 1  # %L name: a local subprogram


@dataclass(frozen=True, slots=True)
class Section:
    """Lines [start, end) of a file that form one program."""

    kind: SectionKind
    name: str  # upper case; "" for a main program without header
    start: int  # first line of the body (after the header line)
    end: int  # index after the last line


@dataclass(slots=True)
class Structure:
    """Where the parts of a control block are: its $ELSE/$CASE lines and its end."""

    parts: list[tuple[StmtKind, int]] = field(default_factory=list)  # (kind, line index)
    close: int = -1  # line index of the closing statement
    after: int = -1  # line index after the closing statement


class Program:
    """One NC file prepared for decoding (sections, caches)."""

    def __init__(self, text: NcText, name: str, parser: LineParser, skip_levels: int,
                 check: SyntaxCheck | None = None) -> None:
        """``text``: the program's text, or its file (a ``Path``), read as a stream
        (``text_pages``; ``OSError`` when it cannot be read). With ``check`` (syntax
        check) an error in a line is reported and the line repositioned after it
        (``check.parse_checked``), never raised."""
        self.check = check
        self.src = SourceText(text, name) if isinstance(text, str) else SourceText.open(text, name)
        self.name = name
        self.parser = parser
        self.skip_levels = skip_levels
        self.main, self.locals = _sections(self.src)
        self._statements: dict[int, tuple[Statement | None, int]] = {}
        self._logical: dict[int, tuple[LogicalLine | None, int]] = {}
        self._structures: dict[int, Structure] = {}
        self._labels: dict[int, dict[str, list[int]]] = {}
        # #VAR line -> (declarations, after)
        self.var_blocks: dict[int, tuple[list[Declaration], int]] = {}

    # ------------------------------------------------------------ lines

    def logical(self, index: int, end: int) -> tuple[LogicalLine | None, int]:
        """The logical line at ``index`` (cached) and the index after it."""
        got = self._logical.get(index)
        if got is None:
            try:
                got = read_logical(self.src, index, end, self.skip_levels)
            except NcError as error:
                if self.check is None:
                    raise
                self.check.report(error, categorize(error, None))
                # an unclosed #COMMENT BEGIN comments out the rest; else skip the line
                got = (None, end if error.id == NcErrorId.COMMENT_BLOCK_NOT_CLOSED else index + 1)
            if len(self._logical) >= CACHE_LINES:
                self._logical.clear()
            self._logical[index] = got
        return got

    def statement(self, index: int, end: int) -> tuple[Statement | None, int]:
        """The parsed statement at ``index`` (cached) and the index after it."""
        got = self._statements.get(index)
        if got is None:
            line, after = self.logical(index, end)
            if line is None:
                got = (None, after)
            elif self.check is None:
                got = (self.parser.parse(line), after)
            else:
                got = (parse_checked(self.parser.parse, line, self.check), after)
            if len(self._statements) >= CACHE_LINES:
                self._statements.clear()
            self._statements[index] = got
        return got

    def local(self, name: str) -> list[Section]:
        """The ``%L`` sections called ``name`` (case-insensitive)."""
        return self.locals.get(name.upper(), [])

    # ------------------------------------------------------------ control blocks

    def keyword(self, index: int, end: int) -> tuple[StmtKind | None, LogicalLine | None, int]:
        """The control keyword of the line at ``index`` without parsing the whole line."""
        line, after = self.logical(index, end)
        if line is None:
            return None, None, after
        m = _KEYWORD_SCAN.match(line.upper)
        if m is None:
            return None, line, after
        if m.group(2) is not None:
            rt_kind = StmtKind.RT_WHILE if m.group(2) == "WHILE" else StmtKind.RT_ENDWHILE
            return rt_kind, line, after
        kind = _KEYWORDS.get(m.group(1))
        if kind == StmtKind.IF and "$GOTO" in line.upper[m.end():]:
            kind = StmtKind.IF_GOTO
        return kind, line, after

    def structure(self, opener: Control, index: int, end: int) -> Structure:
        """The parts and the end of the control block opened at ``index``."""
        found = self._structures.get(index)
        if found is None:
            found = self._scan(opener, index, end)
            self._structures[index] = found
        return found

    def _scan(self, opener: Control, index: int, end: int) -> Structure:
        kind = _OPENER_OF.get(opener.kind, opener.kind)
        wanted = _PARTS.get(kind, ())
        result = Structure()
        stack: list[tuple[StmtKind, LogicalLine]] = []
        k = self.logical(index, end)[1]
        while k < end:
            found, line, after = self.keyword(k, end)
            if found is None or line is None:  # no control keyword (or no code) here
                k = after
                continue
            if found in OPENERS:
                stack.append((found, line))
            elif found in CLOSER_OF:
                expected = CLOSER_OF[found]
                open_kind = stack[-1][0] if stack else kind
                if expected != open_kind:
                    raise _mismatch(found, open_kind, line)
                if stack:
                    stack.pop()
                else:
                    result.close = k
                    result.after = after
                    return result
            elif found in wanted and not stack:
                result.parts.append((found, k))
            k = after
        closer = next(c for c, o in CLOSER_OF.items() if o == kind)
        raise opener.line.error(
            NcErrorId.BLOCK_NOT_CLOSED, f"{SPELLING[kind]} without {SPELLING[closer]}", opener.pos
        )

    # ------------------------------------------------------------ labels

    def find_label(self, section: Section, label: str, after: int) -> int | None:
        """Index of the line defining ``label``: the next one after ``after``, else the
        first one in the section."""
        labels = self._labels.get(section.start)
        if labels is None:
            labels = self._index_labels(section)
            self._labels[section.start] = labels
        where = labels.get(label)
        if not where:
            return None
        for k in where:
            if k > after:
                return k
        return where[0]

    def _index_labels(self, section: Section) -> dict[str, list[int]]:
        labels: dict[str, list[int]] = {}
        k = section.start
        while k < section.end:
            try:
                line, after = self.logical(k, section.end)
            except NcError:  # a broken line is reported when it runs, not by the search
                k += 1
                continue
            if line is not None:
                m = _LABEL_SCAN.match(line.upper)
                assert m is not None  # every part of the pattern is optional: it always matches
                if m.group(2):
                    labels.setdefault(f"N{int(m.group(1))}", []).append(k)
                if m.group(3):
                    labels.setdefault(f"[{m.group(3)}]", []).append(k)
            k = after
        return labels


def _mismatch(found: StmtKind, open_kind: StmtKind, line: LogicalLine) -> NcError:
    err = _CLOSER_ERROR.get(found, NcErrorId.LOOP_END_WITHOUT_BEGIN)
    expected = next(c for c, o in CLOSER_OF.items() if o == open_kind)
    stripped = line.text.lstrip()
    pos = line.text.find("$") if "$" in line.text else len(line.text) - len(stripped)
    if "#" in line.text and found == StmtKind.RT_ENDWHILE:
        pos = line.text.find("#")
    return line.error(
        err, f"{SPELLING[found]} does not match the open {SPELLING[open_kind]} "
        f"(expected {SPELLING[expected]})", pos,
    )


def _sections(src: SourceText) -> tuple[Section, dict[str, list[Section]]]:
    """Main section and local subprograms (by upper-case name) of a file."""
    count = src.count
    headers: list[tuple[int, SectionKind, str]] = []
    in_comment = False
    for line_no, raw in src.marked_lines():
        stripped = raw.lstrip()
        if stripped.startswith("#"):
            directive = comment_directive(raw)
            if directive is not None:
                in_comment = directive == "BEGIN"
            continue
        if in_comment:
            continue
        code = strip_comments(raw)
        local = _LOCAL_HEADER.match(code)
        if local is not None:
            headers.append((line_no, SectionKind.LOCAL, local.group(1).upper()))
        else:
            main_header = _MAIN_HEADER.match(code)
            # marked_lines gives lines whose first non-blank is '%' (not '#', see above),
            # and comments start with '(' or ';': the '%' is still there
            assert main_header is not None
            headers.append((line_no, SectionKind.MAIN, main_header.group(1).upper()))
    bounds = [h[0] for h in headers] + [count]
    locals_: dict[str, list[Section]] = {}
    main: Section | None = None
    for n, (line, kind, name) in enumerate(headers):
        section = Section(kind, name, line + 1, bounds[n + 1])
        if kind == SectionKind.LOCAL:
            locals_.setdefault(name, []).append(section)
        elif main is None:
            main = section
    if main is None:
        main = Section(SectionKind.MAIN, "", 0, bounds[0])
    return main, locals_
