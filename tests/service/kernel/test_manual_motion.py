"""The velocity profile of one manually moved axis (``manual_motion.AxisMotion``), for
any goal, speed, acceleration and software limits: it never changes its velocity by
more than acc * dt per cycle, never leaves the limits, and ends exactly at its goal (cut
at a limit, which it then reports)."""

from __future__ import annotations

from hypothesis import given, settings
from hypothesis import strategies as st

from cnc_objects.service.kernel.manual_motion import AxisDynamicsLimits, AxisMotion

DT_S = 0.001
MAX_CYCLES = 200_000


def run(motion: AxisMotion) -> list[tuple[float, float]]:
    """(position, velocity) per cycle until the motion is at rest."""
    samples = []
    for _ in range(MAX_CYCLES):
        motion.step(DT_S)
        samples.append((motion.position_mm, motion.velocity_mm_s))
        if motion.at_rest:
            return samples
    raise AssertionError("the motion did not come to rest")


def check(samples: list[tuple[float, float]], limits: AxisDynamicsLimits) -> None:
    previous = 0.0
    for position, velocity in samples:
        assert abs(velocity - previous) <= limits.acc_mm_s2 * DT_S * (1 + 1e-9) + 1e-12
        assert abs(velocity) <= limits.vel_mm_s * (1 + 1e-9)
        assert limits.sw_limit_min_mm <= position <= limits.sw_limit_max_mm
        previous = velocity
    assert samples[-1][1] == 0.0


dynamics = st.builds(
    AxisDynamicsLimits,
    vel_mm_s=st.floats(1.0, 200.0), acc_mm_s2=st.floats(50.0, 10_000.0),
    sw_limit_min_mm=st.floats(-50.0, -1.0), sw_limit_max_mm=st.floats(1.0, 50.0),
)


@settings(max_examples=60, deadline=None)
@given(limits=dynamics, start=st.floats(-1.0, 1.0), target=st.floats(-80.0, 80.0))
def test_a_goal_is_reached_exactly_under_the_acceleration(limits, start, target) -> None:
    motion = AxisMotion(start, limits)
    motion.move_to(target)
    samples = run(motion)
    check(samples, limits)
    assert samples[-1][0] == limits.clip(target)
    assert motion.hit_limit == (limits.clip(target) != target)


@settings(max_examples=60, deadline=None)
@given(limits=dynamics, direction=st.sampled_from((1, -1)),
       release_after=st.integers(1, 3000))
def test_a_continuous_jog_brakes_when_released_or_stops_at_the_limit(
        limits, direction, release_after) -> None:
    motion = AxisMotion(0.0, limits)
    motion.run(direction)
    samples = []
    for _ in range(release_after):
        motion.step(DT_S)
        samples.append((motion.position_mm, motion.velocity_mm_s))
        if motion.at_rest:
            break
    motion.stop()
    samples += run(motion) if not motion.at_rest else []
    check(samples, limits)
    limit = limits.sw_limit_max_mm if direction > 0 else limits.sw_limit_min_mm
    if motion.hit_limit:
        assert samples[-1][0] == limit
    else:
        assert samples[-1][0] * direction < limit * direction
