"""A first syntax check: every line of a file parsed, nothing executed.

``check_syntax`` parses each logical line of every section (main program and all local
subprograms, called or not) the way the decoder would and collects the errors instead
of stopping at the first one. It finds what parsing can find (unknown words, malformed
numbers and expressions, unknown control statements and instructions, bad
declarations); errors that need the program to run (undeclared variables, arc
geometry, labels, missing files, unbalanced control blocks) are left to decoding.
The SYNCHK execution mode of a later issue builds on it.
"""

from __future__ import annotations

from .declarations import parse_declaration
from .errors import NcError
from .parser import LineParser, word_table
from .source import SourceText, join_lines, read_logical
from .statements import Control, StmtKind

__all__ = ["check_syntax"]


def check_syntax(text: str, file: str, *, axes: tuple[str, ...],
                 skip_levels: int = 1) -> list[NcError]:
    """All syntax errors of ``text``, in line order (empty when there is none)."""
    parser = LineParser(word_table(tuple(axes)))
    src = SourceText(text, file)
    count = src.count
    errors: list[NcError] = []
    in_var_block = False
    k = 0
    while k < count:
        try:
            line, after = read_logical(src, k, count, skip_levels)
        except NcError as e:  # e.g. an unclosed #COMMENT BEGIN: report, go on
            errors.append(e)
            k += 1
            continue
        k = after
        if line is None or line.upper.lstrip().startswith("%"):
            continue
        try:
            if in_var_block:
                if line.upper.lstrip().startswith("#") and "ENDVAR" in line.upper:
                    in_var_block = False
                    continue
                while line.upper.count("[") > line.upper.count("]") and k < count:
                    more, k = read_logical(src, k, count, skip_levels)
                    if more is not None:
                        line = join_lines(line, more)
                parse_declaration(line)
                continue
            stmt = parser.parse(line)
            if isinstance(stmt, Control) and stmt.kind == StmtKind.VAR:
                in_var_block = True
        except NcError as e:
            errors.append(e)
    return errors
