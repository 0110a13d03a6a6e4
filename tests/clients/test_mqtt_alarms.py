"""The MQTT bridge publishes the alarms (real service, real broker): the active list
retained on ``cnc/<machine>/alarms/active``, one message per event on
``cnc/<machine>/alarms/event`` (docs/mqtt.md, docs/alarms.md)."""

from __future__ import annotations

import json

from cnc_objects.clients import AsyncClient, ChannelError
from tests.support.broker import ONLINE, Broker, Watcher
from tests.support.mqtt_bridge import bridge_config, bridging
from tests.support.service import RunningService

BAD = b"G0 X1\nG1 X10\nM30\n"  # line 2: G1 without F, NC error 20008


def _active_ids(payload: bytes) -> list[int]:
    return [a["id"] for a in json.loads(payload)["active"]]


async def test_alarm_events_and_the_retained_list(service: RunningService,
                                                  broker: Broker) -> None:
    config = bridge_config(service.endpoint, broker, machine="al", objects=("cnc_version_r",))
    async with Watcher(broker, "cnc/al/#") as watcher, bridging(config), \
            AsyncClient(service.endpoint, timeout_s=10) as c:
        await watcher.wait_for("cnc/al/status", ONLINE)
        await watcher.wait_for("cnc/al/alarms/active", lambda p: _active_ids(p) == [])
        await c.upload("bad.nc", BAD)
        await c.run_program("bad.nc", 1)
        try:
            await c.wait_program(1, 30)
        except ChannelError:
            pass  # the program's error: what the alarm is about
        raised = json.loads((await watcher.wait_for("cnc/al/alarms/event")).payload)
        assert (raised["event"], raised["id"], raised["state"]) == ("raised", 20008, "active")
        assert (raised["file"], raised["line"], raised["column"]) == ("bad.nc", 2, 1)
        assert raised["severity"] == 800 and raised["class"] == "decoder"
        await watcher.wait_for("cnc/al/alarms/active", lambda p: _active_ids(p) == [20008])
        mark = watcher.mark()
        await c.acknowledge_alarm(raised["sequence"])
        acked = await watcher.wait_for("cnc/al/alarms/event", since=mark)
        assert json.loads(acked.payload)["event"] == "acknowledged"
        await c.reset(1)
        cleared = await watcher.wait_for(
            "cnc/al/alarms/event", lambda p: json.loads(p)["event"] == "cleared", since=mark)
        assert json.loads(cleared.payload)["sequence"] == raised["sequence"]
        await watcher.wait_for("cnc/al/alarms/active", lambda p: _active_ids(p) == [],
                               since=mark)
        # a subscriber that comes later gets the list, retained, and no old events
        async with Watcher(broker, "cnc/al/alarms/#") as late:
            message = await late.wait_for("cnc/al/alarms/active")
            assert message.retain and _active_ids(message.payload) == []
            assert all(m.topic.value != "cnc/al/alarms/event" for m in late.messages)
