"""``profile.advance``: the closed-form motion within one segment."""

from __future__ import annotations

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cnc_objects.service.kernel.path.profile import advance

from .programs import trapezoid_time


def _walk(length, acc, cap, v0, v1, dt):
    """Advance cycle by cycle to the end: (time used, speeds, positions)."""
    s, v, used = 0.0, v0, 0.0
    speeds, positions = [v], [s]
    for _ in range(1_000_000):
        s, v, left = advance(length, acc, cap, v1, s, v, dt)
        used += dt - left
        speeds.append(v)
        positions.append(s)
        if s == length:
            return used, speeds, positions
    raise AssertionError("did not reach the end")


@settings(max_examples=80, deadline=None)
@given(length=st.floats(0.01, 50), acc=st.floats(100, 20000), cap=st.floats(20, 500),
       f0=st.floats(0, 1), f1=st.floats(0, 1), dt=st.sampled_from([0.001, 0.002]))
def test_time_equals_closed_form_and_limits_hold(length, acc, cap, f0, f1, dt) -> None:
    # entry and exit speeds reachable from each other, below the cap
    v1 = f1 * min(cap, math.sqrt(2 * acc * length))
    v0 = f0 * min(cap, math.sqrt(v1 * v1 + 2 * acc * length))
    used, speeds, positions = _walk(length, acc, cap, v0, v1, dt)
    assert used == pytest.approx(trapezoid_time(length, acc, cap, v0, v1), rel=1e-9, abs=1e-12)
    assert speeds[-1] == v1 and positions[-1] == length
    assert max(speeds) <= cap * (1 + 1e-12)
    for a, b in zip(speeds, speeds[1:]):
        assert abs(b - a) <= acc * dt * (1 + 1e-9)
    for x, v in zip(positions, speeds):  # never above the braking curve
        assert v * v <= v1 * v1 + 2 * acc * (length - x) + 1e-9 * (1 + v * v)
    assert all(b >= a for a, b in zip(positions, positions[1:]))


def test_stop_lands_exactly_on_the_end_without_creeping() -> None:
    used, speeds, positions = _walk(10.0, 5000.0, 100.0, 0.0, 0.0, 0.001)
    assert positions[-1] == 10.0 and speeds[-1] == 0.0
    # from cruise to standing takes (100 / 5000) s = 20 cycles, +1 partial at most
    braking = [k for k, v in enumerate(speeds) if 0 < v < 100.0 and k > len(speeds) // 2]
    assert len(braking) <= 21


def test_decelerates_at_the_limit_when_the_cap_drops() -> None:
    s, v, left = advance(1000.0, 5000.0, 20.0, 0.0, 0.0, 100.0, 0.001)
    assert v == pytest.approx(95.0) and left == 0.0
    assert s == pytest.approx(0.001 * (100 + 95) / 2)


def test_standing_with_cap_zero_consumes_the_cycle() -> None:
    assert advance(10.0, 5000.0, 0.0, 0.0, 3.0, 0.0, 0.001) == (3.0, 0.0, 0.0)


def test_passing_the_end_returns_the_time_left() -> None:
    # 0.05 mm at 100 mm/s, exit 100: end after 0.5 ms
    s, v, left = advance(0.05, 5000.0, 100.0, 100.0, 0.0, 100.0, 0.001)
    assert (s, v) == (0.05, 100.0) and left == pytest.approx(0.0005)
