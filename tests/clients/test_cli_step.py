"""``cnc step``: cycles granted to a service on the step clock; refused elsewhere."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from cnc_objects.testing import ServiceProcess, serving
from tests.support.cli import cnc, json_lines
from tests.support.service import RunningService


@pytest.fixture(scope="module")
def stepped() -> Iterator[ServiceProcess]:
    with serving("--clock", "step") as service:
        yield service


def test_step_runs_the_cycles_and_shows_the_counter(stepped: ServiceProcess) -> None:
    [first] = json_lines(cnc("--json", "step", "5", endpoint=stepped.endpoint))
    assert (first["cycles"], first["cycle"]) == (5, 5)
    assert first["kernel_time_s"] == pytest.approx(0.005)
    one = cnc("step", endpoint=stepped.endpoint)
    assert one.returncode == 0, one.stderr
    assert one.stdout.startswith("cycle 6  kernel time 0.006000 s")


def test_step_of_more_than_the_limit_is_an_ads_error(stepped: ServiceProcess) -> None:
    bad = cnc("step", "100001", endpoint=stepped.endpoint)
    assert bad.returncode == 1 and "0x706" in bad.stderr and "step_max_cycles" in bad.stderr


def test_step_of_zero_is_a_usage_error(stepped: ServiceProcess) -> None:
    assert cnc("step", "0", endpoint=stepped.endpoint).returncode == 2


def test_step_under_the_virtual_clock_is_refused(service: RunningService) -> None:
    bad = cnc("step", endpoint=service.endpoint)
    assert bad.returncode == 1 and "0x707" in bad.stderr and "--clock step" in bad.stderr
