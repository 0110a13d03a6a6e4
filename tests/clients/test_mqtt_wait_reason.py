"""The MQTT bridge publishes why a channel stands: ``mc_wait_reason_r`` (number and name)
and ``mc_wait_reason_text_r``, both in the default set.

A real service on the virtual clock, a real broker and the bridge in the test's event
loop; the program stops at M0, so the reason lasts until the test ends it.
"""

from __future__ import annotations

import json

from cnc_objects.clients import AsyncClient
from cnc_objects.protocol.wait_reasons import WAIT_REASON_TEXTS, WaitReason
from tests.support.broker import ONLINE, Broker, Watcher
from tests.support.mqtt_bridge import bridge_config, bridging
from tests.support.service import RunningService

REASON, TEXT = "cnc/m1/ch1.mc_wait_reason_r", "cnc/m1/ch1.mc_wait_reason_text_r"


async def test_the_wait_reason_is_published_with_its_name_and_text(
    service: RunningService, broker: Broker
) -> None:
    async with Watcher(broker, "cnc/m1/#") as watcher, \
            bridging(bridge_config(service.endpoint, broker)):
        await watcher.wait_for("cnc/m1/status", ONLINE)
        idle = json.loads((await watcher.wait_for(REASON)).payload)
        assert (idle["value"], idle["name"]) == (0, "NONE")
        mark = watcher.mark()
        async with AsyncClient(service.endpoint) as c:
            await c.upload("stop.nc", b"G1 X1 F6000\nM0\nM30\n")
            await c.run_program("stop.nc", 1)
            stopped = json.loads((await watcher.wait_for(
                REASON, lambda p: json.loads(p)["value"] == WaitReason.PROGRAMMED_STOP,
                since=mark)).payload)
            assert list(stopped) == ["value", "name", "ts", "seq"]
            assert stopped["name"] == "PROGRAMMED_STOP"
            text = WAIT_REASON_TEXTS[WaitReason.PROGRAMMED_STOP]
            await watcher.wait_for(TEXT, lambda p: json.loads(p)["value"] == text, since=mark)
            await c.reset(1)
