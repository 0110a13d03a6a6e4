"""``cnc-mqtt``: publish CNC objects to an MQTT broker and take writes from it.

    from cnc_objects.clients.mqtt import Bridge, BridgeConfig
    await Bridge(BridgeConfig("tcp://127.0.0.1:5555", "localhost", "mill1")).run()

Topics and payloads: ``topics`` and ``payloads``; usage: docs/mqtt.md.
"""

from .bridge import Bridge
from .config import DEFAULT_OBJECTS, BridgeConfig, parse_broker
from .topics import Topics

__all__ = ["DEFAULT_OBJECTS", "Bridge", "BridgeConfig", "Topics", "parse_broker"]
