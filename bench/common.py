"""What the bench parts share: the figure of one measurement and the bench machine."""

from __future__ import annotations

import statistics
from dataclasses import dataclass

#: Three channels of six axes: the machine the dispatch and ADS parts serve.
BENCH_MACHINE = """
name = "bench"
physical_axes = [
  {number = 1, name = "X"}, {number = 2, name = "Y"}, {number = 3, name = "Z"},
  {number = 4, name = "A"}, {number = 5, name = "B"}, {number = 6, name = "C"},
]
""" + "".join(
    f"""
[[channels]]
id = {c}
name = "ch{c}"
suspend_output_at_start = {"false" if c == 1 else "true"}
axes = [{", ".join(
        f'{{name = "{n}", logical_number = {10 * c + k}, link_to = {k}}}'
        for k, n in enumerate("XYZABC", start=1))}]
"""
    for c in (1, 2, 3)
) + """
# The bench measures what serving costs, not the rate policy: the token bucket runs (its
# cost is measured) but never holds a request back (the default, 20 000/s, would).
[limits]
requests_per_s_per_client = 10_000_000
"""


@dataclass
class Figure:
    """Throughput and latency of one measurement."""

    reads_s: float
    median_us: float
    p99_us: float


def figure(count: int, elapsed_s: float, latencies_s: list[float]) -> Figure:
    """``count`` operations in ``elapsed_s``, with the latency of each."""
    lat = sorted(latencies_s)
    return Figure(
        count / elapsed_s,
        statistics.median(lat) * 1e6,
        lat[min(len(lat) - 1, int(len(lat) * 0.99))] * 1e6,
    )


def median_figure(figures: list[Figure]) -> Figure:
    """Median of each number over the runs."""
    return Figure(
        statistics.median(f.reads_s for f in figures),
        statistics.median(f.median_us for f in figures),
        statistics.median(f.p99_us for f in figures),
    )
