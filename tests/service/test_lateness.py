"""``LatenessHistogram``: the cycle lateness percentiles of the realtime clock."""

from __future__ import annotations

from cnc_objects.service.kernel.clock import LATENESS_RANGE_US, LatenessHistogram


def test_percentiles_are_the_upper_edge_of_their_10_us_bucket() -> None:
    h = LatenessHistogram()
    assert h.percentile_us(0.5) == 0  # no cycle yet
    for late_us in [3] * 98 + [250, 1234]:
        h.add(late_us)
    assert h.percentile_us(0.5) == 10
    assert h.percentile_us(0.98) == 10
    assert h.percentile_us(0.99) == 260
    assert h.percentile_us(1.0) == 1240


def test_early_and_very_late_cycles_are_clamped_to_the_range() -> None:
    h = LatenessHistogram()
    h.add(-5)
    h.add(10 * LATENESS_RANGE_US)
    assert h.total == 2
    assert h.percentile_us(0.5) == 10
    assert h.percentile_us(1.0) == LATENESS_RANGE_US + 10


def test_reset_forgets_every_cycle() -> None:
    h = LatenessHistogram()
    h.add(500)
    h.reset()
    assert (h.total, h.percentile_us(0.99)) == (0, 0)
