"""The speed profile within one segment, in closed form.

``advance`` moves a path point along one segment for a given time on the fastest
profile the segment allows: accelerate with the segment's acceleration a towards its
speed limit (cap), cruise, and brake with a on the braking curve
v^2 = v_exit^2 + 2 a (L - s) so that the planned exit speed is met exactly at the end.
Above the cap (override lowered, feedhold) it decelerates with a; above the braking
curve (a re-plan lowered it) it brakes with a through the end. Each piece has constant
acceleration, so positions and speeds are exact, not integrated numerically.
"""

from __future__ import annotations

from math import sqrt


def advance(length: float, acc: float, cap: float, exit_: float, s: float, v: float,
            t: float) -> tuple[float, float, float]:
    """Move along one segment for at most ``t`` seconds on the fastest admissible profile.

    ``length`` mm long, acceleration ``acc``, speed limit ``cap``, planned exit speed
    ``exit_``; the path is at ``s`` mm with speed ``v``. Returns (s, v, t_left); when
    the end is reached, s == length exactly and t_left is the unused time (else 0).
    An end reached within a relative 1e-9 of ``t`` (rounding) counts as reached, so a
    stop lands on the end at speed 0 instead of creeping. Standing (cap 0, speed 0)
    uses the whole time.
    """
    d = length - s
    if d <= 0.0:
        return length, v, t
    eps = t * 1e-9  # an end this little beyond the time left counts as reached
    two_a = 2.0 * acc
    brake2 = exit_ * exit_ + two_a * d  # braking curve (speed^2) at s
    v2 = v * v
    # rounding of positions (~1e-16 * length) matters near the end, where v^2 is small
    slack2 = 1e-9 * brake2 + two_a * 1e-12 * (length + 1.0)
    if v2 >= brake2 - slack2:  # on (or above) the braking curve: brake to the end
        v_end = exit_ if v2 <= brake2 + slack2 else sqrt(v2 - two_a * d)
        tau = (v - v_end) / acc
        if tau <= t + eps:
            return length, v_end, max(t - tau, 0.0)
        return s + (v - 0.5 * acc * t) * t, v - acc * t, 0.0
    if v > cap:  # above the speed limit (override lowered, feedhold): decelerate to it
        x = (v2 - cap * cap) / two_a
        if x >= d:  # the end comes first, below the exit speed
            v_end = sqrt(max(v2 - two_a * d, 0.0))
            tau = (v - v_end) / acc
            if tau <= t + eps:
                return length, v_end, max(t - tau, 0.0)
            return s + (v - 0.5 * acc * t) * t, v - acc * t, 0.0
        tau = (v - cap) / acc
        if tau > t:
            return s + (v - 0.5 * acc * t) * t, v - acc * t, 0.0
        s += x
        d -= x
        t -= tau
    elif v < cap:  # accelerate
        peak2 = 0.5 * (v2 + brake2)  # where the acceleration and braking curves meet
        triangle = peak2 < cap * cap
        top2 = peak2 if triangle else cap * cap
        x = (top2 - v2) / two_a
        if x >= d:  # accelerating all the way to the end
            v_end2 = v2 + two_a * d
            v_end = exit_ if abs(v_end2 - exit_ * exit_) <= slack2 else sqrt(v_end2)
            tau = (v_end - v) / acc
            if tau <= t + eps:
                return length, v_end, max(t - tau, 0.0)
            return s + (v + 0.5 * acc * t) * t, v + acc * t, 0.0
        top = sqrt(top2) if triangle else cap
        tau = (top - v) / acc
        if tau > t:
            return s + (v + 0.5 * acc * t) * t, v + acc * t, 0.0
        s += x
        d -= x
        t -= tau
        if triangle:  # brake right away
            tau = (top - exit_) / acc
            if tau <= t + eps:
                return length, exit_, max(t - tau, 0.0)
            return s + (top - 0.5 * acc * t) * t, top - acc * t, 0.0
    # cruise at cap, then brake to the exit speed
    if cap <= 0.0:
        return s, 0.0, 0.0
    if exit_ >= cap:
        tau = d / cap
        if tau <= t + eps:
            return length, cap, max(t - tau, 0.0)
        return s + cap * t, cap, 0.0
    x = d - (cap * cap - exit_ * exit_) / two_a
    if x > 0.0:
        tau = x / cap
        if tau > t:
            return s + cap * t, cap, 0.0
        s += x
        t -= tau
    tau = (cap - exit_) / acc
    if tau <= t + eps:
        return length, exit_, max(t - tau, 0.0)
    return s + (cap - 0.5 * acc * t) * t, cap - acc * t, 0.0
