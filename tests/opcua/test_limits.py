"""``[limits]`` of the OPC UA front end: over each, the status code a client expects and
nothing else changes (docs/opcua.md "Limits")."""

from __future__ import annotations

import asyncio
from collections.abc import Iterator
from contextlib import AsyncExitStack
from pathlib import Path
from typing import Any

import pytest
from asyncua import Client, Node, ua
from asyncua.common.subscription import Subscription

from cnc_objects.testing import ServiceProcess, serving
from tests.opcua.conftest import OPCUA_ANY_PORT, OPCUA_START_S, opcua_url

LIMITS = """
[limits]
opcua_sessions = 2
opcua_subscriptions_per_session = 2
opcua_subscriptions_total = 3
opcua_monitored_items_per_session = 5
opcua_monitored_items_total = 8
opcua_queue_size_max = 3
opcua_notifications_per_publish = 2
"""
#: Variables of the standard address space (their number is all that counts here).
_SERVER_VARIABLES = (
    ua.ObjectIds.Server_ServerStatus_State, ua.ObjectIds.Server_ServerStatus_StartTime,
    ua.ObjectIds.Server_ServerStatus_CurrentTime, ua.ObjectIds.Server_ServiceLevel,
    ua.ObjectIds.Server_ServerStatus_BuildInfo_ProductName,
    ua.ObjectIds.Server_ServerStatus_BuildInfo_SoftwareVersion,
    ua.ObjectIds.Server_ServerStatus_SecondsTillShutdown,
)
_TIMEOUT_S = 30


@pytest.fixture(scope="module")
def limited_service(tmp_path_factory: pytest.TempPathFactory) -> Iterator[ServiceProcess]:
    """A service with small OPC UA limits."""
    config: Path = tmp_path_factory.mktemp("opcua-limits") / "machine.toml"
    config.write_text(LIMITS)
    with serving("--config", str(config), *OPCUA_ANY_PORT, timeout_s=OPCUA_START_S) as service:
        yield service


class _Handler:
    """Keeps the data changes of a subscription; ``got`` is set at ``expected`` of them."""

    def __init__(self, expected: int = 0) -> None:
        self.values: list[Any] = []
        self.expected = expected
        self.got = asyncio.Event()

    def datachange_notification(self, node: Node, val: Any, data: Any) -> None:
        self.values.append(val)
        if len(self.values) >= self.expected:
            self.got.set()


def _variables(client: Client, count: int) -> list[Node]:
    return [client.get_node(ua.NodeId(_SERVER_VARIABLES[k % len(_SERVER_VARIABLES)]))
            for k in range(count)]


async def _assert_reads(client: Client) -> None:
    state = await client.get_node(ua.NodeId(ua.ObjectIds.Server_ServerStatus_State)).read_value()
    assert state == ua.ServerState.Running


async def test_a_session_beyond_the_limit_is_refused_bad_too_many_sessions(
        limited_service: ServiceProcess) -> None:
    url = opcua_url(limited_service)
    async with AsyncExitStack() as stack:
        first = await stack.enter_async_context(Client(url, timeout=_TIMEOUT_S))
        await stack.enter_async_context(Client(url, timeout=_TIMEOUT_S))
        with pytest.raises(ua.uaerrors.BadTooManySessions):
            async with Client(url, timeout=_TIMEOUT_S):
                pass
        await _assert_reads(first)  # the sessions open are served on
    async with Client(url, timeout=_TIMEOUT_S) as again:  # closed sessions make room
        await _assert_reads(again)
    assert limited_service.process.poll() is None


async def test_subscriptions_beyond_the_limits_are_refused_bad_too_many_subscriptions(
        limited_service: ServiceProcess) -> None:
    url = opcua_url(limited_service)
    async with Client(url, timeout=_TIMEOUT_S) as one, Client(url, timeout=_TIMEOUT_S) as two:
        kept = [await one.create_subscription(100, _Handler()) for _ in range(2)]
        with pytest.raises(ua.uaerrors.BadTooManySubscriptions):  # two per session
            await one.create_subscription(100, _Handler())
        await two.create_subscription(100, _Handler())
        with pytest.raises(ua.uaerrors.BadTooManySubscriptions):  # three in all
            await two.create_subscription(100, _Handler())
        # the subscriptions created are served
        assert isinstance(await kept[0].subscribe_data_change(_variables(one, 1)[0]), int)
        await _assert_reads(two)


async def test_monitored_items_beyond_the_limits_are_refused_one_by_one(
        limited_service: ServiceProcess) -> None:
    url = opcua_url(limited_service)
    async with Client(url, timeout=_TIMEOUT_S) as one, Client(url, timeout=_TIMEOUT_S) as two:
        sub_one: Subscription = await one.create_subscription(100, _Handler())
        first = await sub_one.subscribe_data_change(_variables(one, 7))
        assert isinstance(first, list)
        assert [isinstance(a, int) for a in first] == [True] * 5 + [False] * 2  # 5 a session
        assert {a.value for a in first[5:] if isinstance(a, ua.StatusCode)} == {
            ua.StatusCodes.BadTooManyMonitoredItems}
        handler = _Handler()
        sub_two: Subscription = await two.create_subscription(100, handler)
        answers = await sub_two.subscribe_data_change(_variables(two, 5))
        assert isinstance(answers, list)
        assert [isinstance(a, int) for a in answers] == [True] * 3 + [False] * 2  # 8 in all
        # the items created are served, and deleting one makes room for one
        await sub_one.unsubscribe(next(a for a in first if isinstance(a, int)))
        assert isinstance(await sub_two.subscribe_data_change(_variables(two, 1)[0]), int)
        await _assert_reads(one)


async def test_a_queue_size_beyond_the_limit_is_revised_down(
        limited_service: ServiceProcess) -> None:
    async with Client(opcua_url(limited_service), timeout=_TIMEOUT_S) as client:
        sub: Subscription = await client.create_subscription(100, _Handler())
        request = ua.MonitoredItemCreateRequest()
        request.ItemToMonitor = ua.ReadValueId(
            NodeId=ua.NodeId(ua.ObjectIds.Server_ServerStatus_CurrentTime),
            AttributeId=ua.AttributeIds.Value)
        request.MonitoringMode = ua.MonitoringMode.Reporting
        request.RequestedParameters = ua.MonitoringParameters(
            ClientHandle=1, SamplingInterval=100, QueueSize=1000, DiscardOldest=True)
        params = ua.CreateMonitoredItemsParameters(
            SubscriptionId=sub.subscription_id, ItemsToCreate=[request])
        [result] = await client.uaclient.create_monitored_items(params)
    assert result.StatusCode.is_good()
    assert result.RevisedQueueSize == 3


async def test_a_publish_carries_at_most_the_limit_of_notifications(
        limited_service: ServiceProcess) -> None:
    async with Client(opcua_url(limited_service), timeout=_TIMEOUT_S) as client:
        handler = _Handler(expected=5)
        sub: Subscription = await client.create_subscription(100, handler)
        publishes: list[tuple[int, bool]] = []
        publish = sub.publish_callback

        async def counted(result: ua.PublishResult) -> None:
            for data in result.NotificationMessage.NotificationData:
                if isinstance(data, ua.DataChangeNotification):
                    publishes.append((len(data.MonitoredItems), result.MoreNotifications))
            await publish(result)

        # asyncua's client dispatches each PublishResult through this table
        client.uaclient._subscription_callbacks[sub.subscription_id] = counted
        answers = await sub.subscribe_data_change(_variables(client, 5))
        assert isinstance(answers, list) and all(isinstance(a, int) for a in answers)
        await asyncio.wait_for(handler.got.wait(), _TIMEOUT_S)
    assert publishes[:3] == [(2, True), (2, True), (1, False)]

