"""The MQTT bridge in tests: its configuration against a test broker, run for a block,
and the values a watcher saw."""

from __future__ import annotations

import asyncio
import contextlib
import json
from collections.abc import AsyncIterator

from cnc_objects.clients.mqtt import Bridge, BridgeConfig
from tests.support.broker import Broker, Watcher


def bridge_config(endpoint: str, broker: Broker, machine: str = "m1", **options) -> BridgeConfig:
    """A bridge with test timings: it notices a lost service within 1.5 s."""
    timings = {
        "service_timeout_s": 1.0, "probe_s": 0.2, "reconnect_initial_s": 0.05, "reconnect_max_s": 0.5
    }
    return BridgeConfig(
        endpoint, broker.host, machine, broker_port=broker.port, **{**timings, **options}
    )


@contextlib.asynccontextmanager
async def bridging(config: BridgeConfig) -> AsyncIterator[Bridge]:
    """Run a bridge for the block; cancel it (a clean stop) on the way out."""
    bridge = Bridge(config)
    task = asyncio.create_task(bridge.run(), name="bridge under test")
    try:
        yield bridge
    finally:
        task.cancel()
        with contextlib.suppress(asyncio.CancelledError):
            await task


def values_of(watcher: Watcher, machine: str = "m1", until: int | None = None) -> dict[str, dict]:
    """The newest value message of every object the watcher saw (up to index ``until``)."""
    prefix = f"cnc/{machine}/"
    values = {}
    for message in watcher.messages[:until]:
        name = message.topic.value.removeprefix(prefix)
        if "/" not in name and name != "status":
            values[name] = json.loads(message.payload)
    return values
