"""``cnc spindle`` against a fresh service on the virtual clock: show, override, start by
a manual block (S.. M3 waits for the speed: MVS_SVS), stop."""

from __future__ import annotations

from tests.support.cli import cnc, json_lines
from tests.support.service import RunningService


def test_spindle_start_override_show_and_stop(service: RunningService) -> None:
    ep = service.endpoint
    shown = cnc("spindle", endpoint=ep)
    assert shown.returncode == 0, shown.stderr
    assert shown.stdout.splitlines()[0].startswith("channel 1 spindle: M5  S0  ")
    [record] = json_lines(cnc("--json", "spindle", "--override", "50", "--start", "2000",
                              endpoint=ep))
    assert (record["mode"], record["programmed_rpm"], record["override_pct"]) == ("M3", 2000.0,
                                                                                 50.0)
    assert record["commanded_rpm"] == 1000.0  # S x override
    # the manual block ended after the speed was reached (M3 is MVS_SVS)
    assert (record["actual_rpm"], record["speed_reached"]) == (1000.0, True)
    [stopped] = json_lines(cnc("--json", "spindle", "--stop", endpoint=ep))
    assert (stopped["mode"], stopped["actual_rpm"]) == ("M5", 0.0)


def test_spindle_override_out_of_range_is_a_usage_error(service: RunningService) -> None:
    bad = cnc("spindle", "--override", "151", endpoint=service.endpoint)
    assert bad.returncode == 2
    assert "Invalid value for '--override': 151.0 is not in the range 0.0<=x<=150.0" in " ".join(
        bad.stderr.split())


def test_start_and_stop_together_are_refused(service: RunningService) -> None:
    bad = cnc("spindle", "--start", "100", "--stop", endpoint=service.endpoint)
    assert bad.returncode == 2 and "exclude each other" in bad.stderr
