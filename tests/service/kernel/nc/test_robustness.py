"""Property tests: garbage never crashes the decoder; the hot path equals the general one."""

from __future__ import annotations

import dataclasses
from itertools import islice

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from cnc_objects.service.kernel.nc import NcError, NcErrorId, work_guard
from tests.support.nc_programs import (
    nc_text,
    plain_programs,
    valid_arcs,
)

from .support import decoder, slow

MAX_BLOCKS = 300  # endless programs (#RT WHILE) are cut off here




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
