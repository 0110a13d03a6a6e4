"""Source text: comments, comment blocks, skip lines, continuation lines, positions."""

from __future__ import annotations

import pytest

from cnc_objects.service.kernel.nc import NcErrorId

from .support import decode, ends, error_of


@pytest.mark.parametrize(
    "program",
    [
        "G0 X1 ; comment Q5 $%#\nM30",
        "G0 (comment Q5) X1\nM30",
        "G0 X1 (unclosed comment Q5\nM30",
        "(only a comment)\n; another\n\nG0 X1\nM30",
        "#COMMENT BEGIN\nQ5 anything\n%L NOT_A_SECTION\n#COMMENT END\nG0 X1\nM30",
        "  # comment begin\nQ5\n  #comment end\nG0 X1\nM30",
        "G0 X1 ; (\nM30",
    ],
)
def test_comments(program) -> None:
    assert ends(program) == [(1.0, 0.0, 0.0)]


def test_comment_characters_inside_strings_are_text() -> None:
    blocks = decode('#VAR\nV.L.S : STRING = "a;b(c)"\n#ENDVAR\n'
                    '$IF V.L.S == "a;b(c)"\nG0 X1\n$ENDIF\nM30')
    assert len(blocks) == 2


@pytest.mark.parametrize(
    ("program", "err", "line", "column"),
    [
        ("#COMMENT BEGIN\nG0 X1\nM30", NcErrorId.COMMENT_BLOCK_NOT_CLOSED, 1, 1),
        ("G0 X1\n  #COMMENT END\nM30", NcErrorId.COMMENT_END_WITHOUT_BEGIN, 2, 3),
        ("/11 G0 X1\nM30", NcErrorId.INVALID_SKIP_LEVEL, 1, 2),
    ],
)
def test_comment_and_skip_errors(program, err, line, column) -> None:
    e = error_of(program)
    assert (e.id, e.line, e.column) == (err, line, column), str(e)


@pytest.mark.parametrize(
    ("skip_levels", "expected"),
    [
        (0, [1.0, 2.0, 3.0, 4.0]),  # nothing skipped: the "/" lines run
        (1, [1.0, 4.0]),  # "/" and "/1" are level 1 (bit 0)
        (2, [1.0, 2.0, 3.0]),  # bit 1: level 2
        (0b11, [1.0]),
    ],
)
def test_skip_levels(skip_levels, expected) -> None:
    program = "G0 X1\n/ G0 X2\n/1 G0 X3\n/2 G0 X4\nM30"
    assert [e[0] for e in ends(program, skip_levels=skip_levels)] == expected


def test_skipped_line_is_not_decoded() -> None:
    assert ends("/ this line is not decoded at all\nG0 X1\nM30") == [(1.0, 0.0, 0.0)]


def test_not_skipped_line_is_checked() -> None:
    e = error_of("/ ausgeblendete Zeile\nM30", skip_levels=0)
    assert (e.id, e.line, e.column) == (NcErrorId.UNKNOWN_WORD, 1, 3)


def test_continuation_lines() -> None:
    blocks = decode("N10 G1 \\\n  X1 \\\n\n  ; a comment inside\n  Y2 F60\nM30")
    assert len(blocks) == 2
    assert blocks[0].number == 10
    assert blocks[0].motion.end_mm == (1.0, 2.0, 0.0)
    assert (blocks[0].source.line, blocks[1].source.line) == (1, 6)


def test_error_in_a_continuation_line_points_at_its_physical_line() -> None:
    e = error_of("G1 X1 \\\n  F100 \\\n    Q7\nM30")
    assert (e.id, e.line, e.column) == (NcErrorId.UNKNOWN_WORD, 3, 5)


def test_backslash_inside_a_line_is_text() -> None:
    e = error_of("L C:\\ISG\\x.nc\nM30")
    assert e.id == NcErrorId.FILE_NOT_FOUND and "C:\\ISG\\x.nc" in e.message
