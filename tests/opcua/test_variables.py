"""Bound variables over asyncua's client: values that follow a running program through a
subscription, writes under the session's role, and the status codes of bad writes."""

from __future__ import annotations

import asyncio
from typing import Any

import pytest
from asyncua import Client, Node, ua

from cnc_objects.clients import AsyncClient
from cnc_objects.testing import ServiceProcess
from tests.opcua.conftest import CNC_URI, cnc_node, opcua_url

TIMEOUT_S = 60.0
PROGRAM = "G90 G1 X50 F3000\nM30\n"  # 1 s of kernel time from X0 to X50
_S = ua.StatusCodes


class _Values:
    """asyncua's subscription handler: every data change in a queue."""

    def __init__(self) -> None:
        self.queue: asyncio.Queue[Any] = asyncio.Queue()

    def datachange_notification(self, node: Node, value: Any, data: Any) -> None:
        self.queue.put_nowait(value)


async def _override(client: Client) -> Node:
    ns = await client.get_namespace_index(CNC_URI)
    channel = await cnc_node(client, "CncInterface", "CncChannelList", "Channel1")
    return await channel.get_child(f"{ns}:CmdOverride")


async def _status_of_write(node: Node, variant: ua.Variant) -> int:
    """The status code a Write of ``variant`` to ``node`` is answered with."""
    write = ua.WriteValue(NodeId=node.nodeid, AttributeId=ua.AttributeIds.Value,
                          Value=ua.DataValue(variant))
    results = await node.session.write(ua.WriteParameters(NodesToWrite=[write]))
    return int(results[0].value)


async def _until(values: _Values, last: float) -> list[float]:
    """The values of ``values`` up to and including ``last``."""
    seen = [await asyncio.wait_for(values.queue.get(), TIMEOUT_S)]
    while seen[-1] != last:
        seen.append(await asyncio.wait_for(values.queue.get(), TIMEOUT_S))
    return seen


async def test_act_pos_follows_a_running_program_at_the_sampling_interval(
        opcua_service: ServiceProcess, ua_client: Client) -> None:
    """Sampled in kernel time at the subscription's interval: 20 ms gives about 50
    values over the 1 s move, 250 ms about 4."""
    act_pos = await cnc_node(ua_client, "CncInterface", "CncAxisList", "Ch1_X",
                             "PosIndirect", "ActPos")
    fast, slow = _Values(), _Values()
    subscriptions = [await ua_client.create_subscription(20, fast),
                     await ua_client.create_subscription(250, slow)]
    for subscription in subscriptions:
        await subscription.subscribe_data_change(act_pos, queuesize=1000)
    assert await _until(fast, 0.0) == [0.0]
    assert await _until(slow, 0.0) == [0.0]
    async with AsyncClient(opcua_service.endpoint, timeout_s=TIMEOUT_S) as cnc:
        await cnc.upload("opcua.nc", PROGRAM.encode())
        await cnc.run_program("opcua.nc", 1)
        fast_seen, slow_seen = await _until(fast, 50.0), await _until(slow, 50.0)
        await cnc.wait_program(1, TIMEOUT_S)
        await cnc.upload("back.nc", b"G90 G1 X0 F6000\nM30\n")  # for the next tests
        await cnc.run_program("back.nc", 1)
        await cnc.wait_program(1, TIMEOUT_S)
    for subscription in subscriptions:
        await subscription.delete()
    assert fast_seen == sorted(fast_seen)  # the axis moves one way
    assert 30 <= len(fast_seen) <= 70, fast_seen  # and is seen on its way
    assert 2 <= len(slow_seen) <= 8, slow_seen


async def test_an_operator_writes_the_override(ua_client: Client) -> None:
    override = await _override(ua_client)
    assert await _status_of_write(override, ua.Variant(55.5, ua.VariantType.Double)) == _S.Good
    assert await override.read_value() == 55.5  # the reply came once the kernel applied it
    assert await _status_of_write(override, ua.Variant(100.0, ua.VariantType.Double)) == _S.Good


@pytest.mark.parametrize("variant, status", [
    (ua.Variant(50, ua.VariantType.Int32), _S.BadTypeMismatch),
    (ua.Variant("50", ua.VariantType.String), _S.BadTypeMismatch),
    (ua.Variant(-5.0, ua.VariantType.Double), _S.BadOutOfRange),
    (ua.Variant(1000.0, ua.VariantType.Double), _S.BadOutOfRange),
    (ua.Variant(float("nan"), ua.VariantType.Double), _S.BadOutOfRange),
])
async def test_a_bad_write_is_refused_and_changes_nothing(
        ua_client: Client, variant: ua.Variant, status: int) -> None:
    override = await _override(ua_client)
    assert await _status_of_write(override, variant) == status
    assert await override.read_value() == 100.0


async def test_unknown_and_read_only_nodes(ua_client: Client) -> None:
    ns = await ua_client.get_namespace_index(CNC_URI)
    unknown = ua_client.get_node(ua.NodeId("no-such-node", ns))
    value = await unknown.read_data_value(raise_on_bad_status=False)
    assert value.StatusCode.value == _S.BadNodeIdUnknown
    assert await _status_of_write(unknown, ua.Variant(1.0)) == _S.BadNodeIdUnknown
    channel = await cnc_node(ua_client, "CncInterface", "CncChannelList", "Channel1")
    act = await channel.get_child(f"{ns}:ActOverride")
    assert await _status_of_write(act, ua.Variant(50.0)) == _S.BadNotWritable
    vendor = await cnc_node(ua_client, "CncInterface", "VendorName")
    assert await _status_of_write(vendor, ua.Variant("x")) == _S.BadNotWritable
    assert await vendor.read_value() == "cnc-objects"


async def test_a_monitor_may_not_write(monitor_service: ServiceProcess) -> None:
    async with Client(opcua_url(monitor_service), timeout=30) as client:
        override = await _override(client)
        status = await _status_of_write(override, ua.Variant(50.0, ua.VariantType.Double))
        assert status == _S.BadUserAccessDenied
        assert await override.read_value() == 100.0


async def _notifications_until(cnc: AsyncClient, count: int) -> int:
    """``cnc_notifications_r`` once it is ``count`` (read again until then, or the timeout)."""
    deadline = asyncio.get_running_loop().time() + TIMEOUT_S
    while True:
        held = int(await cnc.read("cnc_notifications_r"))
        if held == count or asyncio.get_running_loop().time() > deadline:
            return held


async def test_a_closed_session_frees_its_hub_subscriptions(
        opcua_service: ServiceProcess) -> None:
    async with AsyncClient(opcua_service.endpoint, timeout_s=TIMEOUT_S) as cnc:
        assert await _notifications_until(cnc, 0) == 0
        async with Client(opcua_url(opcua_service), timeout=30) as client:
            ns = await client.get_namespace_index(CNC_URI)
            channel = await cnc_node(client, "CncInterface", "CncChannelList", "Channel1")
            subscription = await client.create_subscription(50, _Values())
            # one object each, and ActProgramStatus of two (state and waiting for start)
            for name in ("ActOverride", "ActFeedrate", "ActProgramStatus"):
                await subscription.subscribe_data_change(await channel.get_child(f"{ns}:{name}"))
            assert await _notifications_until(cnc, 4) == 4
        assert await _notifications_until(cnc, 0) == 0  # the session closed: all freed


async def test_sessions_watching_one_variable_share_its_samples(
        opcua_service: ServiceProcess) -> None:
    """One hub subscription per variable and interval, however many items watch it; it
    ends with the last of them."""
    url = opcua_url(opcua_service)
    async with AsyncClient(opcua_service.endpoint, timeout_s=TIMEOUT_S) as cnc:
        assert await _notifications_until(cnc, 0) == 0
        async with Client(url, timeout=30) as first:
            override = await _override(first)
            values = _Values()
            subscription = await first.create_subscription(50, values)
            await subscription.subscribe_data_change(override)
            async with Client(url, timeout=30) as second:
                others = _Values()
                shared = await second.create_subscription(50, others)
                await shared.subscribe_data_change(await _override(second))
                assert await asyncio.wait_for(others.queue.get(), TIMEOUT_S) == 100.0
                assert await _notifications_until(cnc, 1) == 1  # shared
                await cnc.write("ch1.mc_command_feed_override_w", 777)
                assert await asyncio.wait_for(others.queue.get(), TIMEOUT_S) == 77.7
            assert await _notifications_until(cnc, 1) == 1  # the first session still watches
            assert await asyncio.wait_for(values.queue.get(), TIMEOUT_S) == 100.0
            assert await asyncio.wait_for(values.queue.get(), TIMEOUT_S) == 77.7
            await cnc.write("ch1.mc_command_feed_override_w", 1000)
            assert await asyncio.wait_for(values.queue.get(), TIMEOUT_S) == 100.0
        assert await _notifications_until(cnc, 0) == 0
