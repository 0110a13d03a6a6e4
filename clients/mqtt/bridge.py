"""The MQTT bridge of one machine: service samples out to the broker, writes back in.

    bridge = Bridge(BridgeConfig("tcp://127.0.0.1:5555", "localhost", "mill1"))
    await bridge.run()  # until cancelled

Two sides run side by side and meet in the ``Outbox``. The service side
(``ServiceSource``) keeps the selected objects subscribed and puts each sample into it.
The broker side connects to the broker (TCP_NODELAY: a value message is small and should
leave at once), publishes what the outbox holds as retained QoS 1 messages and serves the
write requests of ``cnc/<machine>/set/#``. Each side reconnects on its own with
exponential backoff; after a broker reconnect every current value is published again,
after a service reconnect the new subscriptions' first samples do the same.
"""

from __future__ import annotations

import asyncio
import logging
import socket

import aiomqtt

from .alarms import AlarmFeed
from .commands import execute_set
from .config import BridgeConfig
from .outbox import OFFLINE, Outbox, Pending
from .payloads import encode_value
from .retry import Backoff, session
from .source import ServiceSource
from .topics import Topics

log = logging.getLogger(__name__)

QOS = 1  # at least once: values, status, will and replies
MAX_INFLIGHT = 256  # QoS 1 publishes waiting for their PUBACK at once
_NODELAY = (socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
_STOP_TIMEOUT_S = 1.0  # for the last "offline" on a clean stop


class Bridge:
    """One machine's bridge between a cnc-service and an MQTT broker.

    ``published`` counts value messages handed to the broker; ``mqtt`` is the broker
    connection while there is one. ``seq`` of a value message is the bridge's count of
    publishes of that object (from 1; it keeps counting across reconnects, so retained
    messages of one bridge run can be ordered by it).
    """

    def __init__(self, config: BridgeConfig) -> None:
        self.config = config
        self.topics = Topics(config.machine)
        self.outbox = Outbox()
        self.alarms = AlarmFeed(self.topics)
        self.source = ServiceSource(config, self.outbox, self.alarms)
        self.mqtt: aiomqtt.Client | None = None
        self.published = 0
        self.broker_connections = 0
        self._seq: dict[str, int] = {}

    async def run(self) -> None:
        """Bridge until cancelled; on cancellation publish ``offline`` and disconnect."""
        async with asyncio.TaskGroup() as tasks:
            tasks.create_task(self.source.run(), name="cnc-mqtt service side")
            tasks.create_task(self._broker_side(), name="cnc-mqtt broker side")

    # ------------------------------------------------------------ broker side

    async def _broker_side(self) -> None:
        config = self.config
        backoff = Backoff(config.reconnect_initial_s, config.reconnect_max_s)
        while True:
            try:
                await session(self._broker_session(backoff), "cnc-mqtt broker session")
            except* aiomqtt.MqttError as group:
                log.warning("broker %s:%d: %s", config.broker_host, config.broker_port,
                            group.exceptions[0])
            await backoff.wait()

    def _new_client(self) -> aiomqtt.Client:
        config = self.config
        return aiomqtt.Client(
            config.broker_host,
            config.broker_port,
            identifier=config.mqtt_client_id,
            username=config.username,
            password=config.password,
            tls_context=config.tls_context,
            will=aiomqtt.Will(self.topics.status, OFFLINE, qos=QOS, retain=True),
            clean_session=True,  # subscriptions are made again on every connect
            keepalive=config.keepalive_s,
            max_inflight_messages=MAX_INFLIGHT,
            socket_options=(_NODELAY,),
            timeout=max(5.0, config.keepalive_s / 2),
        )

    async def _broker_session(self, backoff: Backoff) -> None:
        async with self._new_client() as mqtt:
            # Many publishes wait for their PUBACK at once by design: no warning for that.
            mqtt.pending_calls_threshold = MAX_INFLIGHT * 4
            self.mqtt = mqtt
            self.broker_connections += 1
            backoff.reset()
            log.info("broker %s:%d: connected as %s", self.config.broker_host,
                     self.config.broker_port, self.config.mqtt_client_id)
            try:
                await mqtt.subscribe(self.topics.set_filter, qos=QOS)
                self.outbox.resend_all()
                async with asyncio.TaskGroup() as tasks:
                    tasks.create_task(self._publish(mqtt), name="cnc-mqtt publish")
                    tasks.create_task(self._serve_requests(mqtt), name="cnc-mqtt requests")
                    tasks.create_task(self.alarms.publish(mqtt), name="cnc-mqtt alarms")
            except asyncio.CancelledError:
                # A clean stop says so itself: the broker sends the will only when the
                # connection drops without a DISCONNECT.
                try:
                    await mqtt.publish(self.topics.status, OFFLINE, qos=QOS, retain=True,
                                       timeout=_STOP_TIMEOUT_S)
                except aiomqtt.MqttError as exc:
                    log.warning("could not publish %s on stop: %s", OFFLINE, exc)
                raise
            finally:
                self.mqtt = None

    async def _publish(self, mqtt: aiomqtt.Client) -> None:
        """Publish what the outbox holds: values, then the status.

        Publishes are pipelined: up to ``MAX_INFLIGHT`` wait for their PUBACK at once, and
        new ones go out while older ones wait. Waiting for each batch's acknowledgements
        before the next batch would cost a round trip per batch, and with a broker that
        does not set TCP_NODELAY (Mosquitto's default) a delayed ACK of 40 ms per batch.
        When the window is full the outbox collects newer values meanwhile (keeping only
        the newest of each object).
        """
        window = asyncio.Semaphore(MAX_INFLIGHT)

        async def publish(topic: str, payload: bytes | str) -> None:
            try:
                await mqtt.publish(topic, payload, qos=QOS, retain=True)
            finally:
                window.release()

        async with asyncio.TaskGroup() as tasks:
            while True:
                await self.outbox.wait()
                pending, status = self.outbox.take()
                for item in pending:
                    await window.acquire()
                    topic, payload = self._value_message(item)
                    tasks.create_task(publish(topic, payload))
                if status is not None:
                    await window.acquire()
                    tasks.create_task(publish(self.topics.status, status))
                    log.info("status %s", status)

    def _value_message(self, pending: Pending) -> tuple[str, bytes]:
        """Topic and payload of one value; counts it in ``seq`` and ``published``."""
        info, sample = pending.info, pending.sample
        seq = self._seq[info.name] = self._seq.get(info.name, 0) + 1
        self.published += 1
        payload = encode_value(sample.value, info.unit, sample.timestamp, seq, info.enum,
                               info.scale)
        return self.topics.value(info.name), payload

    async def _serve_requests(self, mqtt: aiomqtt.Client) -> None:
        """Write requests one at a time, in the order they arrive (a program start after
        its program selection stays after it). Replies go out without waiting for their
        PUBACK, so that the next request need not wait for it either."""
        async with asyncio.TaskGroup() as replies:
            async for message in mqtt.messages:
                topic = message.topic.value
                name = self.topics.object_of_set(topic)
                if name is None:
                    continue
                payload = message.payload
                raw = payload if isinstance(payload, bytes) else str(payload).encode()
                outcome = await execute_set(self.source, name, raw, message.retain, topic)
                reply_topic = (
                    self.topics.reply(outcome.request_id) if outcome.request_id
                    else self.topics.no_id_reply
                )
                replies.create_task(mqtt.publish(reply_topic, outcome.body, qos=QOS))
