"""``python -m bench.mqtt_bench``: latency and throughput of the MQTT bridge.

Everything is real and in its own process: ``cnc-service`` (realtime clock, 1 ms cycle),
Mosquitto (the amqtt broker in this process when Mosquitto is missing, which then shares
the event loop with the subscriber: slower figures), and ``cnc-mqtt``.

Latency: this process writes ``ch1.mc_command_feed_override_w`` (a new value each time)
and waits for the bridge's message with that value on
``cnc/bench/ch1.mc_active_feed_override_r``. Measured from just before the write is sent
to the arrival of the message at an MQTT subscriber (aiomqtt, QoS 1), so it includes the
write's way to the kernel, the kernel cycle that applies it, the service's change check
(every ``--cycle-ms`` of kernel time), the bridge, the broker and the subscriber. Median,
90th percentile and maximum of ``--changes`` changes, once per ``--cycle-ms`` given.

Throughput: a program moves X, Y and Z of channel 1 for ``--seconds`` (every position
changes every 1 ms cycle) while the bridge publishes the default objects with
``--cycle-ms 0`` (every change seen by the service). Reported: value messages per second
at the subscriber, and the CPU the bridge process used (100 % = one core). The outbox
keeps only the newest value of each object, so when the broker or the bridge cannot keep
up, intermediate positions are skipped, never queued: the figure is what the bridge
sustains on this machine with service, broker and subscriber beside it.

Publish path alone: a bridge in this process with its service side replaced by a loop
that keeps 100 objects changing as fast as the outbox takes them; value messages handed
to the broker per second (QoS 1, up to 256 waiting for PUBACK). The ceiling of the
bridge's broker side on this machine, with only Mosquitto beside it.
"""

from __future__ import annotations

import argparse
import asyncio
import contextlib
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import AsyncIterator
from datetime import UTC, datetime
from pathlib import Path

import aiomqtt

from cnc_objects.clients import AsyncClient, ObjectInfo, Sample
from cnc_objects.clients.mqtt import Bridge, BridgeConfig
from tests.support.broker import Broker, make_broker
from tests.support.service import ROOT, start_service

MACHINE = "bench"
FEED_R = f"cnc/{MACHINE}/ch1.mc_active_feed_override_r"
PROGRAM = "mqtt-bench.nc"


def start_bridge(endpoint: str, broker: Broker, *args: str) -> subprocess.Popen:
    """``cnc-mqtt`` in a subprocess, its log in a temporary file."""
    return subprocess.Popen(
        [sys.executable, "-m", "cnc_objects.clients.mqtt.cli", "--endpoint", endpoint, "--broker",
         f"{broker.host}:{broker.port}", "--machine", MACHINE, "--log-level", "WARNING", *args],
        cwd=ROOT, stdout=subprocess.DEVNULL, stderr=tempfile.TemporaryFile(mode="w+"),
    )


def cpu_s(pid: int) -> float:
    """User + system CPU seconds of a process so far (Linux /proc)."""
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


async def wait_online(mqtt: aiomqtt.Client, inbox: asyncio.Queue) -> None:
    """Until the bridge says online (its values are out before that)."""
    async with asyncio.timeout(30):
        while True:
            _, topic, payload = await inbox.get()
            if topic.endswith("/status") and payload == b"online":
                return


async def receive(mqtt: aiomqtt.Client, inbox: asyncio.Queue) -> None:
    """Every message, stamped on arrival."""
    async for message in mqtt.messages:
        inbox.put_nowait((time.perf_counter(), message.topic.value, message.payload))


@contextlib.asynccontextmanager
async def bridged(
    endpoint: str, broker: Broker, *bridge_args: str
) -> AsyncIterator[tuple[AsyncClient, asyncio.Queue, subprocess.Popen]]:
    """A ``cnc-mqtt`` process with ``bridge_args``, a subscriber to all its topics whose
    messages land in the queue (stamped on arrival), and a client of the service; the
    bridge is online when this yields and is stopped afterwards."""
    bridge = start_bridge(endpoint, broker, *bridge_args)
    inbox: asyncio.Queue = asyncio.Queue()
    try:
        async with aiomqtt.Client(broker.host, broker.port) as mqtt, AsyncClient(endpoint) as cnc:
            await mqtt.subscribe(f"cnc/{MACHINE}/#", qos=1)
            reader = asyncio.create_task(receive(mqtt, inbox))
            try:
                await wait_online(mqtt, inbox)
                yield cnc, inbox, bridge
            finally:
                reader.cancel()
    finally:
        bridge.terminate()
        bridge.wait(10)


async def latency(endpoint: str, broker: Broker, cycle_ms: int, changes: int) -> list[float]:
    """Seconds from a write to the subscriber's message with the new value, per change."""
    async with bridged(endpoint, broker, "--objects", "ch1.mc_active_feed_override_r",
                       "--cycle-ms", str(cycle_ms)) as (cnc, inbox, _):
        result = []
        for k in range(changes):
            value = 100 + 10 * (k % 80) + (k // 80)  # a new value every time, 0.1 %
            t0 = time.perf_counter()
            await cnc.write("ch1.mc_command_feed_override_w", value)
            while True:
                arrived, topic, payload = await asyncio.wait_for(inbox.get(), 10)
                if topic == FEED_R and json.loads(payload)["value"] == value:
                    result.append(arrived - t0)
                    break
        return result


def motion_program(seconds: float) -> bytes:
    """Back and forth on X, Y and Z at F6000 (100 mm/s) for about ``seconds``."""
    lines = ["G90"]
    for k in range(int(seconds * 2) + 2):  # 50 mm each way: about 0.5 s a move
        lines.append("G01 X50 Y40 Z30 F6000" if k % 2 == 0 else "G01 X0 Y0 Z0")
    return ("\n".join(lines) + "\nM30\n").encode()


async def throughput(endpoint: str, broker: Broker, seconds: float) -> tuple[float, float]:
    """(value messages/s at the subscriber, bridge CPU %) while the axes move."""
    async with bridged(endpoint, broker, "--cycle-ms", "0") as (cnc, inbox, bridge):
        await cnc.reset()
        await cnc.write("ch1.mc_command_feed_override_w", 1000)  # the latency run lowered it
        await cnc.upload(PROGRAM, motion_program(seconds + 1))
        await cnc.run_program(PROGRAM)
        await asyncio.sleep(0.5)  # let the motion get going: measure the steady part
        while not inbox.empty():
            inbox.get_nowait()
        cpu0, t0 = cpu_s(bridge.pid), time.perf_counter()
        await asyncio.sleep(seconds)  # the measurement window
        cpu1, t1 = cpu_s(bridge.pid), time.perf_counter()
        seen = list(inbox._queue)
        count = sum(1 for _, topic, _ in seen if not topic.endswith("/status"))
        await cnc.reset()
        return count / (t1 - t0), 100 * (cpu1 - cpu0) / (t1 - t0)


async def publish_ceiling(broker: Broker, seconds: float, objects: int = 100) -> float:
    """Value messages/s of the bridge's broker side alone, fed without limit.

    A bridge in this process whose service side is replaced by a loop that puts a new
    sample of each of ``objects`` objects into the outbox whenever it has room: what the
    publisher, aiomqtt and paho manage against the broker, without a service.
    """
    config = BridgeConfig("tcp://127.0.0.1:1", broker.host, MACHINE, broker_port=broker.port)
    bridge = Bridge(config)
    infos = [ObjectInfo(f"bench.object_{k}", 553, 0x120101, k, "SGN32", 4, "r", "-", "")
             for k in range(objects)]
    now = datetime.now(UTC)

    async def flood() -> None:
        value = 0
        while True:
            value += 1
            for info in infos:
                bridge.outbox.put(info, Sample(info.name, value, now, value))
            await asyncio.sleep(0)  # let the publisher take them

    bridge.source.run = flood  # type: ignore[method-assign]  # bench only: no service
    task = asyncio.create_task(bridge.run())
    try:
        while bridge.mqtt is None:
            await asyncio.sleep(0.01)
        await asyncio.sleep(0.5)
        count0, t0 = bridge.published, time.perf_counter()
        await asyncio.sleep(seconds)
        return (bridge.published - count0) / (time.perf_counter() - t0)
    finally:
        task.cancel()
        await asyncio.gather(task, return_exceptions=True)


def summary(label: str, samples_s: list[float]) -> str:
    ms = sorted(s * 1000 for s in samples_s)
    p90 = ms[min(len(ms) - 1, int(len(ms) * 0.9))]
    return (f"{label}: median {statistics.median(ms):.2f} ms, p90 {p90:.2f} ms, "
            f"max {ms[-1]:.2f} ms ({len(ms)} changes)")


async def run(args: argparse.Namespace) -> None:
    service = start_service("--clock", "realtime")
    broker = make_broker("auto")
    await broker.start()
    try:
        print(f"service {service.endpoint} (realtime, 1 ms), broker {broker.kind} :{broker.port}")
        for cycle_ms in args.cycle_ms:
            samples = await latency(service.endpoint, broker, cycle_ms, args.changes)
            print(summary(f"latency write -> MQTT, --cycle-ms {cycle_ms}", samples))
        rate, cpu = await throughput(service.endpoint, broker, args.seconds)
        print(f"throughput, 3 axes moving, --cycle-ms 0: {rate:,.0f} value messages/s, "
              f"bridge CPU {cpu:.0f} %")
        ceiling = await publish_ceiling(broker, args.seconds)
        print(f"publish path alone (100 objects, no service): {ceiling:,.0f} value messages/s")
    finally:
        await broker.stop()
        service.stop()


def main(argv: list[str] | None = None) -> None:
    """Parse arguments and run both measurements."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--changes", type=int, default=50, help="changes for the latency")
    parser.add_argument("--cycle-ms", type=int, nargs="+", default=[0, 10],
                        help="--cycle-ms values of the bridge for the latency")
    parser.add_argument("--seconds", type=float, default=3.0, help="throughput window")
    asyncio.run(run(parser.parse_args(argv)))


if __name__ == "__main__":
    main()
