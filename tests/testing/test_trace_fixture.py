"""The plugin's ``cnc_trace`` fixture: a program run's samples as (kernel time ns, object,
value) rows, on a service of the test's own with repeatable samples (issue 37)."""

from __future__ import annotations

import pytest

from cnc_objects.testing.trace import TraceRecorder

PROGRAM = "data/short.nc"
X = "ch1.ax1.command_position_acs"
STATE = "ch1.mc_active_state_r"
ACTIVE = 4


def _check(rows: list[tuple[int, str, object]]) -> None:
    """What every trace of ``PROGRAM`` shows: all first rows at the start, X every 10 ms
    after it, the state on change."""
    start_ns = rows[0][0]
    assert [name for t, name, _ in rows if t == start_ns] == [X, STATE]
    xs = [t for t, name, _ in rows if name == X]
    assert xs == list(range(start_ns, xs[-1] + 1, 10_000_000)) and len(xs) > 10
    states = [(t, v) for t, name, v in rows if name == STATE]
    assert states[1] == (start_ns + 1_000_000, ACTIVE)  # the first cycle after START
    assert all(a[1] != b[1] for a, b in zip(states, states[1:]))  # on change only


def _watch(trace: TraceRecorder) -> None:
    trace.watch([X], cycle_ms=10)
    trace.watch([STATE], cycle_ms=1, on_change=True)


@pytest.mark.cnc_service(programs=[PROGRAM])
def test_cnc_trace_records_a_run(cnc_trace: TraceRecorder) -> None:
    _watch(cnc_trace)
    _check(cnc_trace.run("short.nc"))


@pytest.mark.cnc_service(programs=[PROGRAM], args=["--clock", "step"])
def test_cnc_trace_grants_the_cycles_on_the_step_clock(cnc_trace: TraceRecorder) -> None:
    assert cnc_trace.stepping
    _watch(cnc_trace)
    _check(cnc_trace.run("short.nc"))


def test_a_trace_needs_a_watch(cnc_trace: TraceRecorder) -> None:
    with pytest.raises(ValueError, match="watch some objects first"):
        cnc_trace.run("short.nc")
