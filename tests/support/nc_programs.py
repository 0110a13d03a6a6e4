"""NC programs for the decoder's tests: plain programs and NC text from hypothesis."""

from __future__ import annotations

import math

from hypothesis import strategies as st

_TOKENS = [
    "G0", "G1", "G2", "G3", "G4", "G17", "G18", "G19", "G90", "G91", "G41", "G40", "D1",
    "X10", "Y-5", "Z.5", "I5", "J-5", "K1", "R5", "R-5", "F100", "F0", "S100", "T1", "M3",
    "M0", "M30", "M17", "N10", "N10:", "[L1]", "X", "X[", "]", "[", "1", "+", "-", "*",
    "/", "**", "MOD", "==", "<", "AND", "NOT", "SIN[", "V.L.A", "V.P.B", "V.G.C",
    "V.CYC.D", "V.E.E", "=", ",", '"s"', "$IF", "$ELSEIF", "$ELSE", "$ENDIF", "$WHILE",
    "$ENDWHILE", "$FOR", "$ENDFOR", "$REPEAT", "$UNTIL", "$SWITCH", "$CASE", "$DEFAULT",
    "$BREAK", "$CONTINUE", "$ENDSWITCH", "$GOTO", "$DO", "#VAR", "#ENDVAR", "#RT WHILE",
    "#RT ENDWHILE", "#MSG", "#COMMENT BEGIN", "#COMMENT END", "%L A", "%MAIN", "LL A",
    "L s.nc", "L CYCLE [", "/", "/2", ";", "(", ")", "\\", ":", "TRUE", "V.L.A[1]",
    "V.L.A : UNS32 = -1", "@P1", ".", "1.2.3", "ß", "\t",
]


nc_text = st.lists(
    st.one_of(st.sampled_from(_TOKENS), st.sampled_from(["\n", "\n", " "]),
              st.text(max_size=3)),
    max_size=40,
).map(" ".join)


def _number(draw, low: float, high: float) -> str:
    value = draw(st.floats(low, high, allow_nan=False))
    return draw(st.sampled_from([f"{value:.3f}", f"{value:.0f}", f"{value:.1f}"]))


@st.composite
def motion_lines(draw):
    """A plain motion line in canonical word order (the hot path's kind), valid or not."""
    words = []
    if draw(st.booleans()):
        words.append(f"N{draw(st.integers(0, 10**6))}")
    g = draw(st.sampled_from(["", "G0", "G1", "G2", "G3", "G00", "G01", "G02", "G03"]))
    if g:
        words.append(g)
    for letter in "XYZIJK":
        if draw(st.integers(0, 3)) == 0:
            words.append(letter + _number(draw, -50, 50))
    if draw(st.integers(0, 3)) == 0:
        words.append("F" + _number(draw, -10, 3000))
    spaces = draw(st.sampled_from([" ", "", "  "]))
    tail = draw(st.sampled_from(["", " ; c", ";"]))
    return [spaces.join(words) + tail]


@st.composite
def valid_arcs(draw):
    """An arc whose end point lies on its circle, wherever it starts (incremental)."""
    i = draw(st.floats(-20, 20).filter(lambda v: abs(v) > 0.01))
    j = draw(st.floats(-20, 20))
    angle = draw(st.floats(0, 2 * math.pi))
    r = math.hypot(i, j)
    dx = i + r * math.cos(angle)  # end - start = (centre - start) + radius vector
    dy = j + r * math.sin(angle)
    g = draw(st.sampled_from(["G2", "G3"]))
    return ["G17 G91", f"{g} X{dx:.4f} Y{dy:.4f} I{i:.4f} J{j:.4f}", "G90"]


_MODAL_LINES = ["G90", "G91", "G17", "G18", "G19", "G41 D1", "G40", "F500", "G1", "D2"]


@st.composite
def plain_programs(draw):
    parts = draw(st.lists(
        st.one_of(motion_lines(), valid_arcs(), st.sampled_from(_MODAL_LINES).map(lambda x: [x])),
        max_size=25,
    ))
    return [line for part in parts for line in part]
