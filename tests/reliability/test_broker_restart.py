"""The MQTT broker stopped and started again under the bridge, several times: each time
the bridge reconnects and republishes every object, including a value that changed
while the broker was down, and says it is online again.

The broker is the tests' own (``tests.support.broker``: Mosquitto when installed, else
amqtt), restarted on the same port without persistence, so everything a subscriber sees
afterwards was published anew by the bridge.
"""

from __future__ import annotations

import asyncio
import contextlib
import time

from cnc_objects.clients import AsyncClient
from cnc_objects.clients.mqtt import Bridge, BridgeConfig
from cnc_objects.clients.mqtt.config import DEFAULT_OBJECTS
from cnc_objects.testing import serving
from tests.reliability import figures
from tests.reliability.scale import Scale
from tests.support.broker import ONLINE, Watcher, running_broker

MACHINE = "rel"
STATUS = f"cnc/{MACHINE}/status"
OVERRIDE = f"cnc/{MACHINE}/ch1.mc_active_feed_override_r"
REPUBLISH_TIMEOUT_S = 30.0
NODE = "tests/reliability/test_broker_restart.py"


async def test_the_bridge_republishes_after_every_broker_restart(run_scale: Scale) -> None:
    with serving() as service:
        async with running_broker() as broker, AsyncClient(service.endpoint) as client:
            config = BridgeConfig(
                service.endpoint, broker.host, MACHINE, broker_port=broker.port,
                objects=(*DEFAULT_OBJECTS, "ch1.mc_active_feed_override_r"),
                service_timeout_s=2.0, probe_s=0.2, reconnect_initial_s=0.05,
                reconnect_max_s=0.5,
            )
            bridge = Bridge(config)
            task = asyncio.create_task(bridge.run(), name="bridge under test")
            republished_s = []
            try:
                async with Watcher(broker, f"cnc/{MACHINE}/#") as watcher:
                    await watcher.wait_for(STATUS, ONLINE, timeout_s=REPUBLISH_TIMEOUT_S)
                for cycle in range(run_scale.broker_restarts):
                    await broker.stop()
                    value = 300 + 10 * cycle  # 0.1 %: changed while the broker is down
                    await client.write("ch1.mc_command_feed_override_w", value)
                    await broker.start()
                    started = time.monotonic()
                    async with Watcher(broker, f"cnc/{MACHINE}/#") as watcher:
                        await watcher.wait_for(STATUS, ONLINE, timeout_s=REPUBLISH_TIMEOUT_S)
                        # the payload's value is in % (engineering units), raw in 0.1 %
                        await watcher.wait_value(OVERRIDE, lambda v, value=value: v == value / 10,
                                                 timeout_s=REPUBLISH_TIMEOUT_S)
                    republished_s.append(time.monotonic() - started)
                    assert bridge.broker_connections >= cycle + 2
                assert not task.done(), "the bridge stopped"
            finally:
                task.cancel()
                with contextlib.suppress(asyncio.CancelledError):
                    await task
                await client.write("ch1.mc_command_feed_override_w", 1000)
    print(f"\n{run_scale.broker_restarts} broker ({broker.kind}) restarts: republished within "
          f"{max(republished_s):.2f} s each")
    figures.record(f"MQTT broker ({broker.kind}) restarts under the bridge",
                   f"{run_scale.broker_restarts} x, republished within "
                   f"{max(republished_s):.2f} s", NODE)
