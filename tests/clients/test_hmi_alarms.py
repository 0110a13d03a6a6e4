"""The HMI's alarm line and alarm page (clients/hmi/alarms.py) driven by textual's Pilot
against a real service: an NC error shows on the line, the page lists it and
acknowledges it by key, RESET clears it (docs/alarms.md)."""

from __future__ import annotations

from cnc_objects.clients.client import AsyncClient
from cnc_objects.clients.hmi.alarms import AlarmPage
from cnc_objects.clients.hmi.app import HmiApp
from tests.support.hmi import SIZE, started, wait_until
from tests.support.service import RunningService


async def test_alarm_line_and_page_acknowledge_and_reset(service: RunningService) -> None:
    ep = service.endpoint
    async with AsyncClient(ep) as c, HmiApp(ep).run_test(size=SIZE) as pilot:
        app = await started(pilot)
        line = app.alarm_line
        await wait_until(pilot, lambda: line.listed is not None, what="alarms read")
        assert line.text == "no active alarms"
        await c.upload("bad.nc", b"G0 X1\nG1 X10\nM30\n")
        await c.run_program("bad.nc")
        await wait_until(pilot, lambda: "20008" in line.text, what=lambda: line.text)
        assert line.text.startswith("alarm #1 active error 20008 ch1: bad.nc:2:1: ")
        assert line.has_class("unacknowledged")

        await pilot.press("A")
        await wait_until(pilot, lambda: isinstance(app.screen, AlarmPage), what="alarm page")
        page = app.screen
        assert isinstance(page, AlarmPage)
        await wait_until(pilot, lambda: page.active.row_count == 1, what="active row")
        assert page.active.get_row_at(0)[:5] == ["1", "active", "error", "20008", "1"]
        await pilot.press("k")
        await wait_until(pilot, lambda: page.active.get_row_at(0)[1] == "acknowledged",
                         what=lambda: str(page.active.get_row_at(0)))
        assert str(page.status.render()) == "alarm #1 acknowledged"
        assert line.has_class("acknowledged") and not line.has_class("unacknowledged")
        await pilot.press("escape")
        await wait_until(pilot, lambda: not isinstance(app.screen, AlarmPage), what="closed")

        await pilot.press("r")  # RESET: the error is cleared, the history keeps it
        await wait_until(pilot, lambda: line.text == "no active alarms", what=lambda: line.text)
        assert line.listed is not None and line.listed.history[0].state.name == "CLEARED"
        await pilot.press("A")
        await wait_until(pilot, lambda: isinstance(app.screen, AlarmPage), what="alarm page")
        page = app.screen
        assert isinstance(page, AlarmPage)
        await wait_until(pilot, lambda: page.history.row_count == 1, what="history row")
        await pilot.press("K")  # nothing active: acknowledge all is done at once
        await wait_until(pilot, lambda: "acknowledged" in str(page.status.render()))
