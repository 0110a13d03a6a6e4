"""Words of a block: N, M, S, T, G4, unknown words; where a block comes from."""

from __future__ import annotations

from collections.abc import Callable

import pytest

from cnc_objects.service.kernel.nc import NcErrorId, SourceRef, StopKind

from .support import decode, ends, error_of, slow


def test_block_numbers_and_labels() -> None:
    blocks = decode("N10 G0 X1\nN20: G0 X2\nG0 X3\nN0030 G0 X4\nM30")
    assert [b.number for b in blocks] == [10, 20, None, 30, None]


@pytest.mark.parametrize(
    ("program", "expected"),
    [
        # program -> [(stop, m_functions, spindle, tool)] of the blocks
        ("M3 S1000\nM30", [(StopKind.NONE, (3,), 1000.0, None),
                           (StopKind.PROGRAM_END, (), None, None)]),
        ("T5 M6\nM30", [(StopKind.NONE, (6,), None, 5), (StopKind.PROGRAM_END, (), None, None)]),
        ("M0\nM1\nM2", [(StopKind.PROGRAMMED, (), None, None),
                        (StopKind.OPTIONAL, (), None, None),
                        (StopKind.PROGRAM_END, (), None, None)]),
        ("M8 M3 M30", [(StopKind.PROGRAM_END, (8, 3), None, None)]),
        ("S0\nM05\nM30", [(StopKind.NONE, (), 0.0, None), (StopKind.NONE, (5,), None, None),
                          (StopKind.PROGRAM_END, (), None, None)]),
    ],
)
def test_technology_and_stops(program, expected) -> None:
    got = [(b.stop, b.m_functions, b.spindle_speed_rpm, b.tool) for b in decode(program)]
    assert got == expected


def test_nothing_after_m30_is_decoded() -> None:
    blocks = decode("G0 X1\nM30\nthis is not NC at all\n")
    assert blocks[-1].stop == StopKind.PROGRAM_END
    assert len(blocks) == 2


def test_motion_and_m30_in_one_block() -> None:
    (block,) = decode("G0 X5 M30")
    assert block.motion is not None and block.stop == StopKind.PROGRAM_END


@pytest.mark.parametrize(
    ("program", "dwell"),
    [("G4 X2\nM30", 2.0), ("G4 F1.5\nM30", 1.5), ("G04 X0.25\nM30", 0.25)],
)
def test_dwell(program, dwell) -> None:
    block = decode(program)[0]
    assert block.dwell_s == dwell and block.motion is None and block.needs_stop


def test_dwell_does_not_change_the_feed() -> None:
    blocks = decode("G1 F600 X1\nG4 F2\nX2\nM30")
    assert blocks[2].motion.feed_mm_s == 10.0


def test_dwell_x_word_without_an_x_axis() -> None:
    assert decode("G4 X3\nM30", axes=("Y", "Z"))[0].dwell_s == 3.0


@pytest.mark.parametrize(
    ("program", "err", "line", "column"),
    [
        ("Q5\nM30", NcErrorId.UNKNOWN_WORD, 1, 1),
        ("G0 X1 A5\nM30", NcErrorId.UNKNOWN_WORD, 1, 7),
        ("G0 X1 @\nM30", NcErrorId.UNKNOWN_WORD, 1, 7),
        ("G0 X1 .5\nM30", NcErrorId.UNKNOWN_WORD, 1, 7),
        ("N10 N20 X1\nM30", NcErrorId.BLOCK_NUMBER_TWICE, 1, 5),
        ("N1.5 X1\nM30", NcErrorId.INVALID_BLOCK_NUMBER, 1, 1),
        ("N X1\nM30", NcErrorId.MISSING_VALUE, 1, 1),
        ("G33 X1\nM30", NcErrorId.UNSUPPORTED_G_CODE, 1, 1),
        ("G1.5 X1\nM30", NcErrorId.UNSUPPORTED_G_CODE, 1, 1),
        ("M3.5\nM30", NcErrorId.INVALID_M_CODE, 1, 1),
        ("M-3\nM30", NcErrorId.INVALID_M_CODE, 1, 1),
        ("M0 M30", NcErrorId.CONFLICTING_M_CODES, 1, 4),
        ("S-100\nM30", NcErrorId.INVALID_SPINDLE_SPEED, 1, 1),
        ("T1.5\nM30", NcErrorId.INVALID_TOOL_NUMBER, 1, 1),
        ("G4\nM30", NcErrorId.INVALID_DWELL, 1, 1),
        ("G4 X-1\nM30", NcErrorId.INVALID_DWELL, 1, 4),
        ("G4 X1 F2\nM30", NcErrorId.INVALID_DWELL, 1, 7),
        ("G4 X1 Y2\nM30", NcErrorId.INVALID_DWELL, 1, 7),
        ("M17\nM30", NcErrorId.SUBPROGRAM_END_IN_MAIN, 1, 1),
        ("G0 X1\n\n; end\n", NcErrorId.MISSING_PROGRAM_END, 1, 1),
        ("", NcErrorId.MISSING_PROGRAM_END, 1, 1),
        ("N1 METB=0.0005\nM30", NcErrorId.VALUE_OUT_OF_RANGE, 1, 4),
        ("VFBT=0\nM30", NcErrorId.VALUE_OUT_OF_RANGE, 1, 1),
        ("VFBT=1.01\nM30", NcErrorId.VALUE_OUT_OF_RANGE, 1, 1),
        ("BBTRC=2.5\nM30", NcErrorId.VALUE_OUT_OF_RANGE, 1, 1),
        ("BBTRC=0\nM30", NcErrorId.VALUE_OUT_OF_RANGE, 1, 1),
        ("METB 0.01\nM30", NcErrorId.EXPRESSION_SYNTAX, 1, 1),
        # numbers beyond the float range (G9...9 raised OverflowError: a decoder fault)
        ("G" + "9" * 400 + " X1 F600\nM30", NcErrorId.VALUE_OUT_OF_RANGE, 1, 1),
        ("G1 X" + "9" * 400 + " F600\nM30", NcErrorId.VALUE_OUT_OF_RANGE, 1, 4),
        ("M" + "9" * 400 + "\nM30", NcErrorId.VALUE_OUT_OF_RANGE, 1, 1),
    ],
)
def test_word_errors(program, err, line, column) -> None:
    e = error_of(program)
    assert (e.id, e.line, e.column) == (err, line, column), str(e)


def test_unknown_word_message() -> None:
    assert error_of("G0 X1 Q5\nM30").message == "unknown word 'Q5'"
    assert str(error_of("G0 X1 Q5\nM30")) == "error 21220: prog.nc:1:7: unknown word 'Q5'"


def test_source_reference_of_blocks() -> None:
    text = "%P\n  N1 G0 X1\n\tG0 X2 ; tab\nG0 X3 (c)\nM30\n"
    sources = [b.source for b in decode(text, file="a.nc")]
    assert sources == [
        SourceRef("a.nc", 2, 3, 3), SourceRef("a.nc", 3, 2, 14),
        SourceRef("a.nc", 4, 1, 27), SourceRef("a.nc", 5, 1, 37),
    ]
    # the general path gives the same lines and columns
    assert [(s.line, s.column) for s in (b.source for b in decode(slow(text)))] == [
        (2, 3), (3, 2), (4, 1), (5, 1)
    ]


def test_byte_offsets_count_utf8_bytes_and_crlf() -> None:
    text = "; Grüße\r\nG0 X1\r\nM30\r\n"
    blocks = decode(text)
    assert [(b.source.line, b.source.offset) for b in blocks] == [(2, 11), (3, 18)]


def test_byte_order_mark_counts_in_offsets() -> None:
    blocks = decode("\ufeffG0 X1\nM30")
    assert [b.source.offset for b in blocks] == [3, 9]  # 3 bytes of BOM + 'G0 X1\n'


def test_lower_case_is_accepted() -> None:
    blocks = decode("n5 g1 x10 f600\nm30")
    assert blocks[0].number == 5 and blocks[0].motion.end_mm == (10.0, 0.0, 0.0)


def test_manual_flag() -> None:
    blocks = decode("G0 X1", manual=True)
    assert [b.manual for b in blocks] == [True]
    assert not decode("G0 X1\nM30")[0].manual


@pytest.mark.parametrize("as_text", [lambda t: t, slow], ids=["hot path", "general path"])
def test_an_axis_word_takes_an_expression_after_an_equals_sign(
        as_text: Callable[[str], str]) -> None:
    """ISG ("Axis commands", tf5200_programming_manual/206043659.html): ``X=100`` and
    ``X = <expr>`` as for multi-letter axis names; brackets optional after '='."""
    program = "V.G.NP[1].V.X = 0\nG0 X=100 Y = 2*3 Z=-[1+2]\nG1 X=V.G.NP[1].V.X+1 F100\nM30"
    assert ends(as_text(program)) == [(100.0, 6.0, -3.0), (1.0, 6.0, -3.0)]


@pytest.mark.parametrize(("program", "err", "column"), [
    ("G0 X=", NcErrorId.MISSING_VALUE, 4),
    ("G0 X=\"A\"", NcErrorId.TYPE_MISMATCH, 6),
    ("G0 X==1", NcErrorId.MISSING_VALUE, 4),
])
def test_bad_axis_words_with_an_equals_sign(program: str, err: int, column: int) -> None:
    error = error_of(program + "\nM30")
    assert (error.id, error.line, error.column) == (err, 1, column)
