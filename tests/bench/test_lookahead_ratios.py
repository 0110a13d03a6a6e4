"""Regression test of the look-ahead benchmark's figures (``bench/lookahead_bench.py``).

The ratios are deterministic (virtual clock), so the margin only allows for deliberate
small changes of the interpolation: the measured values are within 0.2 % of the
optimum (see docs/lookahead.md), the bound is the issue's target of 1 %. A clear
regression of the planner, the section planner or the interpolator fails here.
"""

from __future__ import annotations

import pytest

from bench.lookahead_bench import TARGET, Variant, covers_stop, machine, run_program
from bench.lookahead_programs import alternating, circle_arcs, circle_chords, pocket, spiral

PROGRAMS = {p.name: p for p in (spiral(), pocket(), alternating(), circle_arcs(1.0),
                                 circle_chords(1.0))}


@pytest.mark.parametrize("name", sorted(PROGRAMS))
@pytest.mark.parametrize("variant", [Variant(120, False), Variant(120, True)],
                         ids=lambda v: v.label)
def test_ratio_to_the_optimum(name: str, variant: Variant) -> None:
    program = PROGRAMS[name]
    result = run_program(program, variant)
    assert result.violations == []
    assert result.end_error_mm == 0.0  # ends exactly at the programmed end point
    assert result.ratio >= 1.0 - 1e-3 / result.optimum_s  # never faster than the limit
    if variant.la_on or covers_stop(program, variant.buffer_blocks, machine(120)):
        assert result.ratio <= TARGET, f"{name} {variant.label}: {result.ratio:.4f}"
        assert result.warnings == []
    else:  # 120 blocks of 1 um do not cover the stop: the buffer slows the path down
        assert result.ratio > 2.0
        assert result.warnings == [50301]


def test_a_short_buffer_is_slower_but_within_the_limits() -> None:
    result = run_program(PROGRAMS["circle_chords_r1"], Variant(30, False))
    assert result.violations == []
    assert result.end_error_mm == 0.0
    assert result.ratio > 5.0  # 30 um ahead: sqrt(2 * 5000 * 0.03) = 17 mm/s at most
    assert result.warnings == [50301]
