"""``cnc-hmi`` shows the tool and the work offset of each channel (headless Pilot, real
service on the virtual clock); every assertion waits for what the subscriptions bring."""

from __future__ import annotations

from cnc_objects.clients.client import AsyncClient
from cnc_objects.clients.hmi.app import HmiApp
from cnc_objects.testing import run_program_async
from tests.support.hmi import SIZE, started, wait_until
from tests.support.service import RunningService


async def test_tool_d_and_offset_are_shown(service: RunningService) -> None:
    ep = service.endpoint
    async with AsyncClient(ep) as c, HmiApp(ep).run_test(size=SIZE) as pilot:
        app = await started(pilot)
        table = app.tooling
        assert [table.cell("ch1", k) for k in ("tool", "selected", "d", "offset")] == [
            "-", "-", "D0", "G53"]
        await c.write("ch1.wz[2].laenge", 50.0 * 10_000)
        await c.upload("tool.nc", b"T2 M6\nD2\nG56\nT3\nM30\n")
        status = await run_program_async(c, "tool.nc")
        assert status.state == "READY"

        def shown() -> list[str]:
            return [table.cell("ch1", k)
                    for k in ("tool", "selected", "d", "radius", "length", "offset")]

        expected = ["T2", "T3", "D2", "2.5000", "50.0000", "G56"]
        await wait_until(pilot, lambda: shown() == expected, what=lambda: repr(shown()))
        assert table.cell("ch2", "tool") == "-"  # the other channel has its own
