"""``ThrottledWarning``: the first occurrence logged, later ones counted into a line."""

from __future__ import annotations

import logging

import pytest

from cnc_objects.service.log_throttle import ThrottledWarning


def test_first_logged_then_counted_until_the_interval_has_passed(
    caplog: pytest.LogCaptureFixture,
) -> None:
    log = logging.getLogger("test-throttle")
    warning = ThrottledWarning(log, "frame dropped", every_s=0.0)  # every one may log
    quiet = ThrottledWarning(log, "reply dropped", every_s=3600.0)
    with caplog.at_level(logging.WARNING, logger="test-throttle"):
        for k in range(3):
            quiet.note(f"#{k}")
        warning.note("a")
    assert [r.getMessage() for r in caplog.records] == [
        "reply dropped: #0", "frame dropped: a"]
    assert quiet.count == 3


def test_the_next_line_says_how_many_went_unlogged(caplog: pytest.LogCaptureFixture) -> None:
    log = logging.getLogger("test-throttle")
    warning = ThrottledWarning(log, "frame dropped", every_s=3600.0)
    with caplog.at_level(logging.WARNING, logger="test-throttle"):
        for k in range(5):
            warning.note(f"#{k}")
        warning._logged_s -= 3600.0
        warning.note("#5")
    assert [r.getMessage() for r in caplog.records] == [
        "frame dropped: #0",
        "frame dropped: #5 (and 4 more in the last 3600 s, 6 since start)"]
