"""The bridge against the in-process amqtt broker, always: the fallback the broker
fixture uses where Mosquitto is not installed works too (values, retained messages,
writes, the last will, a clean stop)."""

from __future__ import annotations

import json
from collections.abc import AsyncIterator

import pytest

from tests.support.broker import OFFLINE, ONLINE, Broker, Watcher, running_broker
from tests.support.mqtt_bridge import bridge_config, bridging, values_of
from tests.support.mqtt_cli import kill_and_see_the_last_will
from tests.support.service import RunningService


@pytest.fixture
async def amqtt_broker() -> AsyncIterator[Broker]:
    """amqtt in this event loop, on a free port."""
    async with running_broker("amqtt") as running:
        assert running.kind == "amqtt"
        yield running


async def test_bridge_on_amqtt(service: RunningService, amqtt_broker: Broker) -> None:
    broker = amqtt_broker
    config = bridge_config(service.endpoint, broker, machine="a1",
                           writable=("ch1.mc_command_feed_override_w",))
    async with Watcher(broker, "cnc/a1/#") as watcher:
        async with bridging(config) as bridge:
            online = await watcher.wait_for("cnc/a1/status", ONLINE)
            until = watcher.messages.index(online)
            assert set(values_of(watcher, "a1", until)) == {i.name for i in bridge.source.selected}

            async with Watcher(broker, "cnc/a1/#") as late:  # retained values and status
                await late.wait_for("cnc/a1/status", ONLINE)
                await late.wait_for("cnc/a1/ch1.mc_active_state_r")
                assert all(m.retain for m in late.messages)

            await watcher.client.publish("cnc/a1/set/ch1.mc_command_feed_override_w",
                                         json.dumps({"value": 25, "id": "w1"}), qos=1)
            reply = await watcher.wait_for("cnc/a1/reply/w1")
            assert json.loads(reply.payload) == {"ok": True}
            mark = watcher.mark()
        await watcher.wait_for("cnc/a1/status", OFFLINE, since=mark)  # the clean stop


async def test_last_will_on_amqtt(endpoint: str, amqtt_broker: Broker) -> None:
    await kill_and_see_the_last_will(endpoint, amqtt_broker, "a2")
