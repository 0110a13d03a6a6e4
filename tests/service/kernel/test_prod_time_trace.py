"""The PROD_TIME trace recorder: even thinning, the end point kept, the store's size."""

from __future__ import annotations

import pytest

from cnc_objects.clients.path_trace import parse_trace
from cnc_objects.service.kernel.prod_time_trace import ProdTimeTrace, trace_file_name


def _trace(cycles: int, rows_max: int) -> ProdTimeTrace:
    trace = ProdTimeTrace("p.nc", 1, ("X", "Y"), 0.001, rows_max=rows_max)
    for k in range(cycles):
        trace.record(k * 0.001, (float(k), -float(k)), float(k), 1.0, 2.0, 7)
    return trace


def test_every_cycle_while_below_rows_max() -> None:
    trace = _trace(10, rows_max=100)
    assert trace.stride == 1
    assert [row[0] for row in trace.rows] == pytest.approx([k * 0.001 for k in range(10)])


def test_thinning_keeps_even_spacing_and_the_last_cycle() -> None:
    trace = _trace(1001, rows_max=64)
    rows = trace.rows
    assert len(rows) <= 64 + 1
    cycles = [round(row[0] / 0.001) for row in rows]
    assert cycles[0] == 0 and cycles[-1] == 1000  # first and end point
    steps = {b - a for a, b in zip(cycles[:-1], cycles[1:-1])}
    assert steps == {trace.stride} and trace.stride == 16  # 1001 cycles / 16 < 64 rows


def test_file_fits_the_store_and_parses_back() -> None:
    trace = _trace(5001, rows_max=10_000)
    data = trace.csv_bytes("READY", max_bytes=20_000)
    assert len(data) <= 20_000
    parsed = parse_trace(data.decode())
    assert parsed.stride > 1 and parsed.ended == "READY" and parsed.program == "p.nc"
    assert parsed.axis("x")[-1] == 5000.0 and parsed.axis("Y")[-1] == -5000.0
    assert parsed.t_s[-1] == pytest.approx(5.0)
    spacing = {round(d / 0.001) for d in (parsed.t_s[1:-1] - parsed.t_s[:-2])}
    assert spacing == {parsed.stride}


def test_rows_max_must_allow_two_rows() -> None:
    with pytest.raises(ValueError, match="at least 2"):
        ProdTimeTrace("p.nc", 1, ("X",), 0.001, rows_max=1)


def test_file_name_is_per_channel() -> None:
    assert trace_file_name(2) == "prodtime02.csv"


@pytest.mark.parametrize("text, message", [
    ("", "not a PROD_TIME trace"),
    ("t_s,X_mm\n0,1\n", "not a PROD_TIME trace"),
    ("# cnc-objects PROD_TIME trace: program p, channel 1, cycle 1 ms, every 1. cycle, "
     "ended READY\nt_s,X_mm,v\n", "unexpected trace columns"),
    ("# cnc-objects PROD_TIME trace: program p, channel 1, cycle 1 ms, every 1. cycle, "
     "ended READY\nt_s,X_mm,path_mm,v_mm_s,feed_limit_mm_s,line\n0,1,2\n", "3 values"),
])
def test_parse_refuses_what_is_not_a_trace(text: str, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        parse_trace(text)
