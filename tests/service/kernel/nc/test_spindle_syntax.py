"""ISG's spindle-specific syntax ``S[...]`` (IS/tf5200_programming_manual/208178187.html):
the decoder turns each command of the bracket into the word of the plain block form."""

from __future__ import annotations

import pytest

from cnc_objects.service.kernel.nc.errors import NcErrorId

from .support import decode, error_of


@pytest.mark.parametrize(("bracket", "plain"), [
    ("S[REV100 POS45 M19 M3]", "S100 S.POS=45 M19 M3"),  # ISG's example, M19 with M3
    ("S[M3 REV500 M19 POS45 M18 M15 H20]", "M3 S500 M19 S.POS=45 M18 M15 H20"),
    ("S[M03 REV1000]", "M3 S1000"),
    ("S [ M4 REV = 2 * 100 ]", "M4 S200"),
    ("S[REV=200 M19 POS=-45]", "S200 M19 S.POS=315"),
    ("G01 X5 F600 S[M5 \\ H7] M8", "G01 X5 F600 M5 H7 M8"),  # '\\': ISG's separator
    ("S[REV[3 + 4] M3]", "S7 M3"),
])
def test_s_bracket_is_the_plain_block(bracket: str, plain: str) -> None:
    a = decode(f"{bracket}\nM30\n")[0]
    b = decode(f"{plain}\nM30\n")[0]
    assert (a.m_functions, a.h_functions, a.spindle_speed_rpm, a.spindle_pos_deg,
            a.motion) == (b.m_functions, b.h_functions, b.spindle_speed_rpm,
                          b.spindle_pos_deg, b.motion)


def test_s_with_a_bracket_expression_is_still_the_speed() -> None:
    first = decode("S[500 * 2] M3\nM30\n")[0]
    assert (first.spindle_speed_rpm, first.m_functions) == (1000.0, (3,))


@pytest.mark.parametrize(("text", "error", "column"), [
    ("S[M3 REV100 FOO]", NcErrorId.SPINDLE_COMMAND_UNKNOWN, 13),
    ("S[M3 REV100 G1]", NcErrorId.SPINDLE_COMMAND_UNKNOWN, 13),
    ("S[M3 REV]", NcErrorId.MISSING_VALUE, 6),
    ("S[REV M3]", NcErrorId.MISSING_VALUE, 3),
    ("S[M3 REV100 M4]", NcErrorId.SPINDLE_M_TWICE, 13),
    ("S[M19 M5 REV100]", NcErrorId.SPINDLE_M_TWICE, 7),
    ("S[M3 REV100", NcErrorId.EXPRESSION_SYNTAX, 1),
    ("S[REV-100]", NcErrorId.NEGATIVE_SPINDLE_REV, 3),
    ("S[REV100 POS1 POS2]", NcErrorId.SPINDLE_POS_TWICE, 15),
    ("S100 M19 S.POS=1 S.POS=2", NcErrorId.SPINDLE_POS_TWICE, 18),
    ("S100 S[REV200]", NcErrorId.WORD_REPEATED, 8),
    ("S[REV200] S100", NcErrorId.WORD_REPEATED, 11),
    ("S[M3 REV100 D1]", NcErrorId.D_IN_SPINDLE_SYNTAX, 13),
    ("S[REV100 G167]", NcErrorId.INSTRUCTION_NOT_SUPPORTED, 10),
    ("S[REV100 CALLAX]", NcErrorId.INSTRUCTION_NOT_SUPPORTED, 10),
    ("S[REV100 FEED_LINK]", NcErrorId.INSTRUCTION_NOT_SUPPORTED, 10),
    ("S[M19]", NcErrorId.M19_WITHOUT_SPEED, 3),
    ("S100 M3 S2[M4 REV5000]", NcErrorId.UNKNOWN_SPINDLE_NAME, 9),  # one spindle: S
    ("M19 S.POS=90", NcErrorId.M19_WITHOUT_SPEED, 1),  # ISG: "a valid speed (> 0)"
    ("S0 M3 M19", NcErrorId.M19_WITHOUT_SPEED, 7),
])
def test_bad_s_brackets(text: str, error: NcErrorId, column: int) -> None:
    e = error_of(f"G01 X1 F600\n{text}\nM30\n")
    assert (e.id, e.line, e.column) == (error, 2, column)


def test_m19_takes_the_speed_of_an_earlier_block() -> None:
    blocks = decode("S[REV150]\nS[M19 M4]\nM30\n")
    assert blocks[1].m_functions == (19, 4)
