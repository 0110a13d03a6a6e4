"""The MQTT bridge against a real service and a real broker (Mosquitto when installed).

The bridge runs in the test's event loop; a ``Watcher`` (an MQTT client) records what the
broker delivers, and every test waits for the message it expects, with a timeout.
"""

from __future__ import annotations

import json
import socket
from datetime import UTC, datetime, timedelta

from cnc_objects.clients import AsyncClient
from cnc_objects.protocol.values import ChannelMode, ChannelState, LinkState
from tests.support.broker import OFFLINE, ONLINE, Broker, Watcher, free_port
from tests.support.mqtt_bridge import bridge_config, bridging, values_of
from tests.support.service import RunningService, start_service


async def test_publishes_every_object_then_online_and_offline_on_stop(
    endpoint: str, broker: Broker
) -> None:
    async with Watcher(broker, "cnc/m1/#") as watcher:
        async with bridging(bridge_config(endpoint, broker)) as bridge:
            online = await watcher.wait_for("cnc/m1/status", ONLINE)
            before_online = watcher.messages.index(online)
            values = values_of(watcher, until=before_online)
            # Every selected object's value went out before "online".
            assert set(values) == {info.name for info in bridge.source.selected}
            assert len(values) == 129  # the default set on the default machine (docs/mqtt.md)
            assert {"ch1.mc_active_state_r", "ch2.mc_active_mode_r", "ax3.actual_position_acs",
                    "ch1.ax1.link_state", "ch2.mc_error_8_warning_r",
                    "ch1.actual_block_number"} <= set(values)
            # The shared service's values depend on earlier tests: check the form only.
            position = values["ch1.ax1.command_position_acs"]
            # in engineering units, the object's own value beside it
            assert isinstance(position["raw"], int) and position["raw_unit"] == "0.1 um"
            assert position["unit"] == "mm" and position["value"] == position["raw"] / 10_000
            assert position["seq"] == 1
            ts = datetime.fromisoformat(position["ts"].replace("Z", "+00:00"))
            assert ts.tzinfo is not None and abs(datetime.now(UTC) - ts) < timedelta(minutes=1)
            program = values["ch1.mc_active_program_name_r"]
            assert isinstance(program["value"], str) and "unit" not in program  # unitless
            assert "name" not in program and "name" not in position  # not enumerations
            # Enumeration objects carry the name of their value next to the number.
            enumerations = {"ch1.mc_active_state_r": ChannelState,
                            "ch2.mc_active_mode_r": ChannelMode, "ch1.ax1.link_state": LinkState}
            for name, value_set in enumerations.items():
                message = values[name]
                assert message["name"] == value_set(message["value"]).name, message
                assert list(message) == ["value", "name", "ts", "seq"]  # no unit: unitless
            assert isinstance(values["ch1.mc_error_1_warning_r"]["value"], bool)

            # The broker connection has TCP_NODELAY (read back from the bridge's socket).
            sock = bridge.mqtt._client.socket()  # paho's socket under aiomqtt
            assert sock.getsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY) != 0

            # A subscriber that comes later gets the retained values and the status.
            async with Watcher(broker, "cnc/m1/#") as late:
                await late.wait_for("cnc/m1/status", ONLINE)
                await late.wait_for("cnc/m1/ax1.actual_position_acs")
                assert all(m.retain for m in late.messages)
            mark = watcher.mark()
        # A clean stop publishes "offline" itself (retained).
        await watcher.wait_for("cnc/m1/status", OFFLINE, since=mark)
    async with Watcher(broker, "cnc/m1/status") as late:
        assert (await late.wait_for("cnc/m1/status")).payload == b"offline"


async def test_publishes_changes_from_service_notifications(broker: Broker) -> None:
    # Virtual time at wall speed: the 10 mm move takes about 0.2 s, sampled every 10 ms.
    service = start_service("--speed", "1")
    config = bridge_config(service.endpoint, broker, cycle_ms=10)
    async with Watcher(broker, "cnc/m1/#") as watcher, bridging(config):
        await watcher.wait_for("cnc/m1/status", ONLINE)
        async with AsyncClient(service.endpoint) as client:
            before = await client.mdi("G01 X10 F6000")
            await client.wait_mdi(before, timeout_s=10)
        last = await watcher.wait_value("cnc/m1/ch1.ax1.command_position_acs", lambda v: v == 10.0)
        await watcher.wait_value("cnc/m1/ax1.actual_position_acs", lambda v: v == 10.0)
        moves = [json.loads(m.payload) for m in watcher.messages
                 if m.topic.value == "cnc/m1/ch1.ax1.command_position_acs"]
        assert len(moves) >= 5  # the start value, points on the way, the end
        assert [m["seq"] for m in moves] == list(range(1, len(moves) + 1))
        assert [m["ts"] for m in moves] == sorted(m["ts"] for m in moves)
        assert moves[-1] == last and (last["raw"], last["unit"]) == (100000, "mm")
        # The axis that did not move published nothing but its value 0.
        assert {json.loads(m.payload)["value"] for m in watcher.messages
                if m.topic.value == "cnc/m1/ch1.ax2.command_position_acs"} == {0}
    assert service.stop() == 0


FEED = "cnc/m1/set/ch1.mc_command_feed_override_w"
# (topic suffix, payload, reply topic suffix, expected reply without "error")
REQUESTS = [
    ("set/ch1.mc_command_feed_override_w", {"value": 50, "id": "ok-1"}, "reply/ok-1", {"ok": True}),
    ("set/CH1.MC_Command_Feed_Override_W", {"value": 60.0, "id": "case"}, "reply/case", {"ok": True}),
    ("set/ch1.mc_command_feed_override_w", {"raw": 650, "id": "raw"}, "reply/raw", {"ok": True}),
    ("set/ch1.mc_command_execution_mode_w", {"value": 0, "id": "not-writable"},
     "reply/not-writable", {"ok": False, "code": "0x704"}),
    ("set/ch1.mc_active_feed_override_r", {"value": 1, "id": "read-only"},
     "reply/read-only", {"ok": False, "code": "0x704"}),
    ("set/ch1.no_such_object", {"value": 1, "id": "unknown"}, "reply/unknown",
     {"ok": False, "code": "0x710"}),
    ("set/ch1.mc_command_feed_override_w", {"value": "fast", "id": "type"},
     "reply/type", {"ok": False, "code": "0x706"}),
    ("set/ch1.mc_command_feed_override_w", {"value": 200, "id": "range"},
     "reply/range", {"ok": False, "code": "0x706"}),
    ("set/ch1.mc_command_feed_override_w", {"raw": 70000, "id": "uns16"},
     "reply/uns16", {"ok": False, "code": "0x706"}),
    ("set/ch1.mc_command_feed_override_w", {"id": "no-value"}, "reply/no-value",
     {"ok": False, "code": "0x70b"}),
    ("set/ch1.mc_command_feed_override_w", b"{not json", "reply",
     {"ok": False, "code": "0x70b", "topic": FEED}),
    ("set/ch1.mc_command_feed_override_w", [1, 2], "reply", {"ok": False, "code": "0x70b", "topic": FEED}),
    ("set/ch1.mc_command_feed_override_w", {"value": 1, "id": 7}, "reply",
     {"ok": False, "code": "0x70b", "topic": FEED}),
    ("set/ch1.mc_command_feed_override_w", {"value": 1, "id": "a/b"}, "reply",
     {"ok": False, "code": "0x70b", "topic": FEED}),
    ("set/ch1.mc_command_feed_override_w", {"value": 70}, "reply", {"ok": True, "topic": FEED}),
]


async def test_writes_allowed_refused_and_malformed(service: RunningService, broker: Broker) -> None:
    config = bridge_config(
        service.endpoint, broker,
        objects=("@default", "ch1.mc_active_feed_override_r"),
        writable=("ch1.mc_command_feed_override_w", "ch1.mc_active_*_override_r"),
    )
    async with Watcher(broker, "cnc/m1/#") as watcher:
        # A retained request is refused when the bridge subscribes (it would run again at
        # every connect); the bridge is not running yet.
        await watcher.client.publish("cnc/m1/set/ch1.mc_command_feed_override_w",
                                     json.dumps({"value": 100, "id": "kept"}), qos=1, retain=True)
        async with bridging(config):
            reply = await watcher.wait_for("cnc/m1/reply/kept")
            assert json.loads(reply.payload)["code"] == "0x704"
            await watcher.client.publish("cnc/m1/set/ch1.mc_command_feed_override_w", b"", retain=True)
            await watcher.wait_for("cnc/m1/status", ONLINE)
            await watcher.wait_value("cnc/m1/ch1.mc_active_feed_override_r", lambda v: v == 100)

            for suffix, payload, reply_suffix, expected in REQUESTS:
                mark = watcher.mark()
                body = payload if isinstance(payload, bytes) else json.dumps(payload)
                await watcher.client.publish(f"cnc/m1/{suffix}", body, qos=1)
                reply = json.loads((await watcher.wait_for(f"cnc/m1/{reply_suffix}", since=mark)).payload)
                error = reply.pop("error", None)
                assert reply == expected, (suffix, payload, error)
                assert (error is None) == expected["ok"]
                if not expected["ok"]:
                    assert error.startswith(f"ADS {expected['code']} ")

            # The accepted writes reached the kernel, the refused ones did not.
            await watcher.wait_value("cnc/m1/ch1.mc_active_feed_override_r", lambda v: v == 70)
            active = [json.loads(m.payload)["value"] for m in watcher.messages
                      if m.topic.value == "cnc/m1/ch1.mc_active_feed_override_r"]
            changes = [v for k, v in enumerate(active) if k == 0 or v != active[k - 1]]
            assert changes == [100, 50, 60, 65, 70]  # in % (engineering units)


async def test_broker_restart_republishes_current_values(endpoint: str, broker: Broker) -> None:
    async with bridging(bridge_config(endpoint, broker)) as bridge:
        async with Watcher(broker, "cnc/m1/#") as watcher:
            await watcher.wait_for("cnc/m1/status", ONLINE)
        assert bridge.broker_connections == 1
        await broker.restart()  # the same port; the retained messages are gone with it
        async with Watcher(broker, "cnc/m1/#") as watcher:
            await watcher.wait_for("cnc/m1/status", ONLINE)
            value = json.loads((await watcher.wait_for("cnc/m1/ch2.ax3.command_position_acs")).payload)
            assert value["seq"] >= 2  # published again: the new broker had nothing
            assert len(values_of(watcher)) == 129
        assert bridge.broker_connections >= 2


async def test_service_restart_resubscribes(broker: Broker) -> None:
    endpoint = f"tcp://127.0.0.1:{free_port()}"
    first = start_service("--endpoint", endpoint)
    config = bridge_config(endpoint, broker)
    async with Watcher(broker, "cnc/m1/#") as watcher, bridging(config) as bridge:
        await watcher.wait_for("cnc/m1/status", ONLINE)
        mark = watcher.mark()
        assert first.stop() == 0
        # No answer to the probe: the bridge says the machine is offline ...
        await watcher.wait_for("cnc/m1/status", OFFLINE, since=mark)
        second = start_service("--endpoint", endpoint)
        try:
            # ... and online again once it has subscribed on the new service.
            await watcher.wait_for("cnc/m1/status", ONLINE, since=mark)
            assert bridge.source.sessions >= 2
            async with AsyncClient(endpoint) as client:
                await client.wait_mdi(await client.mdi("G01 Y5 F6000"), timeout_s=10)
            moved = await watcher.wait_value("cnc/m1/ch1.ax2.command_position_acs",
                                              lambda v: v == 5.0, since=mark)  # mm
            assert moved["seq"] >= 3  # first session's value, the republish, the move
        finally:
            assert second.stop() == 0
