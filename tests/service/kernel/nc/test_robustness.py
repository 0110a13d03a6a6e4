"""Property tests: garbage never crashes the decoder; the hot path equals the general one."""

from __future__ import annotations

import dataclasses
import math
from itertools import islice

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from cnc_objects.service.kernel.nc import NcError, NcErrorId, work_guard

from .support import decoder, slow

MAX_BLOCKS = 300  # endless programs (#RT WHILE) are cut off here

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


def _outcome(text: str, limit: int = MAX_BLOCKS, **kw):
    """(blocks without byte offsets, error as (id, line, column) or None)."""
    blocks = []
    try:
        for block in islice(decoder(text, **kw).blocks(), limit):
            source = dataclasses.replace(block.source, offset=0)
            blocks.append(dataclasses.replace(block, source=source))
    except NcError as e:
        assert e.id != NcErrorId.INTERNAL_ERROR, str(e)
        return blocks, (e.id, e.line, e.column)
    return blocks, None


@settings(max_examples=300, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(text=nc_text, manual=st.booleans())
def test_garbage_raises_only_nc_errors(monkeypatch, text, manual) -> None:
    monkeypatch.setattr(work_guard, "IDLE_STEPS_MAX", 200)
    files = {"s.nc": text}
    _outcome(text, manual=manual, files=files)


@settings(max_examples=200, deadline=None)
@given(st.text(max_size=60))
def test_random_text_raises_only_nc_errors(text) -> None:
    _outcome(text)


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


@settings(max_examples=300, deadline=None)
@given(plain_programs())
def test_hot_path_gives_the_same_result_as_the_general_path(lines) -> None:
    text = "\n".join(["F1000"] + lines + ["M30"])
    assert _outcome(text) == _outcome(slow(text))


def test_hot_path_equivalence_on_a_generated_program() -> None:
    from bench.decoder_bench import generate_program

    text = generate_program(3000)
    fast = _outcome(text, limit=10**6)
    assert fast[1] is None and len(fast[0]) > 2500
    assert fast == _outcome(slow(text), limit=10**6)


@settings(max_examples=30, deadline=None)
@given(valid_arcs())
def test_valid_arcs_of_the_strategy_decode(lines) -> None:
    blocks, error = _outcome("\n".join(["F100"] + lines + ["M30"]))
    assert error is None and blocks[0].motion.center_mm is not None


def test_loop_without_fast_constructors_gives_the_same_blocks(monkeypatch) -> None:
    """The generated loop also works with the ordinary dataclass constructors (used
    on interpreters where the construct twins are not available)."""
    from cnc_objects.service.kernel.nc import fastpath

    program = "N1 G1 X1 Y2 F600\nG2 X3 Y2 I1\nG0 Z5 ; up\nM30"
    expected = _outcome(program)
    monkeypatch.setattr(fastpath, "FAST", False)
    fastpath.decoding_loop.cache_clear()
    try:
        assert "MAKE_BLOCK" in fastpath.loop_source(("X", "Y", "Z"))
        assert _outcome(program) == expected
    finally:
        fastpath.decoding_loop.cache_clear()
