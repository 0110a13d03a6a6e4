"""The software-limit screening of end-point records against the path preparation's check."""

from __future__ import annotations

import math
import random

import pytest

from cnc_objects.service.kernel.nc.blocks import MotionKind
from cnc_objects.service.kernel.path.endpoints import first_violation
from cnc_objects.service.kernel.path.errors import PathError, PathErrorId
from cnc_objects.service.kernel.path.geometry import Arc, Line
from cnc_objects.service.kernel.path.limits import check_software_limits

LIMITS = [(-50.0, 50.0), (-50.0, 50.0), (-20.0, 20.0)]


def _reference(start, records) -> int | None:
    """Index of the first record whose element leaves the limits (element check)."""
    position = start
    for k, (_, kind, end, centre) in enumerate(records):
        if type(centre) is tuple:
            element = Arc.from_points(position, end, centre, (0, 1), kind == MotionKind.ARC_CCW)
        else:
            element = Line(position, end)
        try:
            check_software_limits(element, LIMITS)
        except PathError:
            return k
        position = end
    return None


def _random_batch(rng: random.Random) -> list:
    position = (0.0, 0.0, rng.uniform(-19, 19))
    records = []
    for line in range(rng.randint(1, 40)):
        if rng.random() < 0.5:
            end = (position[0] + rng.uniform(-15, 15), position[1] + rng.uniform(-15, 15),
                   position[2])
            records.append((line, MotionKind.LINEAR, end, 0))
        else:
            centre = (position[0] + rng.uniform(-10, 10), position[1] + rng.uniform(-10, 10))
            radius = math.hypot(position[0] - centre[0], position[1] - centre[1])
            angle = rng.uniform(0.0, 2 * math.pi)
            end = (centre[0] + radius * math.cos(angle), centre[1] + radius * math.sin(angle),
                   position[2])
            kind = rng.choice((MotionKind.ARC_CW, MotionKind.ARC_CCW))
            records.append((line, kind, end, centre))
        position = end
    return records


def test_the_screening_finds_exactly_the_first_record_the_element_check_refuses() -> None:
    rng = random.Random(6)
    hits = 0
    for _ in range(3000):
        records = _random_batch(rng)
        start = (0.0, 0.0, 0.0)
        found = first_violation(start, records, (0, 1), LIMITS)
        expected = _reference(start, records)
        assert (None if found is None else found[0]) == expected
        hits += expected is not None
    assert 300 < hits < 2700  # both outcomes were exercised


def test_an_arc_whose_bulge_crosses_a_limit_is_found_though_both_ends_are_inside() -> None:
    # clockwise about (47, -5), radius 5.39: through angle 0 at X 52.4
    records = [(0, MotionKind.LINEAR, (45.0, 0.0, 0.0), 0),
               (1, MotionKind.ARC_CW, (45.0, -10.0, 0.0), (47.0, -5.0))]
    ccw = [records[0], (1, MotionKind.ARC_CCW, (45.0, -10.0, 0.0), (47.0, -5.0))]
    assert first_violation((0.0, 0.0, 0.0), ccw, (0, 1), LIMITS) is None  # the other side
    found = first_violation((0.0, 0.0, 0.0), records, (0, 1), LIMITS)
    assert found is not None and found[0] == 1
    assert found[1].id == PathErrorId.SW_LIMIT_MAX


@pytest.mark.parametrize("end, error", [((0.0, 0.0, -25.0), PathErrorId.SW_LIMIT_MIN),
                                        ((60.0, 0.0, 0.0), PathErrorId.SW_LIMIT_MAX)])
def test_an_end_point_outside_is_found_with_its_direction(end, error) -> None:
    found = first_violation((0.0, 0.0, 0.0), [(0, MotionKind.LINEAR, end, 0)], None, LIMITS)
    assert found is not None and found[1].id == error
