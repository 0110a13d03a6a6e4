"""The terminal HMI's channel table shows why a channel stands (``mc_wait_reason_r``).

The HMI against a real service on the virtual clock; the program stops at M0 and a
feedhold comes from the HMI's own key, so each reason lasts until the test ends it.
"""

from __future__ import annotations

from cnc_objects.clients.client import AsyncClient
from cnc_objects.clients.hmi.app import HmiApp
from tests.support.hmi import LONG_PROGRAM, SIZE, shown, started, wait_until
from tests.support.service import RunningService


async def test_channel_table_shows_the_wait_reason(service: RunningService) -> None:
    ep = service.endpoint
    async with AsyncClient(ep) as c, HmiApp(ep).run_test(size=SIZE) as pilot:
        app = await started(pilot)
        assert app.channels.cell("ch1", "waits") == "-"
        await c.upload("stop.nc", b"G1 X1 F6000\nM0\nM30\n")
        await c.run_program("stop.nc", 1)
        await wait_until(pilot, lambda: app.channels.cell("ch1", "waits") == "programmed stop",
                         what=shown(app))
        await c.reset(1)
        await wait_until(pilot, lambda: app.channels.cell("ch1", "waits") == "-")

        await c.upload("long.nc", LONG_PROGRAM)
        await c.run_program("long.nc", 1)
        await wait_until(pilot, lambda: app.channels.cell("ch1", "state") == "ACTIVE")
        await pilot.press("h")  # the HMI's feedhold key
        await wait_until(pilot, lambda: app.channels.cell("ch1", "waits") == "feed hold",
                         what=shown(app))
        await c.reset(1)
