"""The twin's alarms as OPC UA events (real service, virtual clock, asyncua's client):
a bad program's alarm arrives as a CncAlarmType event (Server object) and an AlertType
event (MachineTool Notification/Messages) with its fields; Acknowledge over OPC UA is
the acknowledge of ``cnc alarms ack`` (the twin's alarm object shows it); a monitor's is
refused; ConditionRefresh sends the active ones again (docs/opcua.md, "Alarms as
events")."""

from __future__ import annotations

import asyncio
from collections.abc import Callable, Iterator
from typing import Any

import pytest
from asyncua import Client, ua
from asyncua.common.events import get_filter_from_event_type

from cnc_objects.clients import ChannelError
from cnc_objects.clients import Client as CncClient
from cnc_objects.protocol.alarm_values import AlarmState
from cnc_objects.testing import ServiceProcess
from tests.support.opcua_machine import (
    WAIT_S,
    Running,
    child,
    connected,
    machine_node,
    serving_opcua,
)

CNC_URI = "http://opcfoundation.org/UA/CNC"
MT_URI = "http://opcfoundation.org/UA/MachineTool/"
BAD = "G0 X1\nG1 X10\nM30\n"  # line 2: G1 without F, NC error 20008
ACKNOWLEDGE = ua.NodeId(ua.ObjectIds.AcknowledgeableConditionType_Acknowledge)
REFRESH = ua.NodeId(ua.ObjectIds.ConditionType_ConditionRefresh)


@pytest.fixture(scope="module")
def machine(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[ServiceProcess, str]]:
    with serving_opcua(tmp_path_factory.mktemp("alarm-events")) as running:
        yield running


@pytest.fixture(scope="module")
def monitored(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[ServiceProcess, str]]:
    """A service whose OPC UA sessions are monitors."""
    with serving_opcua(tmp_path_factory.mktemp("alarm-events-monitor"),
                       '[opcua]\nloopback_role = "monitor"\n') as running:
        yield running


class _Events:
    """Events of a subscription, as they come."""

    def __init__(self) -> None:
        self.seen: list[Any] = []
        self.changed = asyncio.Condition()

    async def event_notification(self, event: Any) -> None:
        async with self.changed:
            self.seen.append(event)
            self.changed.notify_all()

    async def wait(self, test: Callable[[Any], bool], after: int = 0) -> Any:
        """The first event from ``after`` on (seen or to come) that passes ``test``."""
        async with asyncio.timeout(WAIT_S), self.changed:
            while True:
                for event in self.seen[after:]:
                    if test(event):
                        return event
                await self.changed.wait()


def fail(service: ServiceProcess, name: str = "bad.nc") -> int:
    """Run a bad program (channel 1 ends in ERROR); the alarm's sequence number."""
    with CncClient(service.endpoint, timeout_s=WAIT_S) as cnc:
        cnc.reset(1)
        cnc.upload(name, BAD.encode())
        cnc.run_program(name, 1)
        with pytest.raises(ChannelError):
            cnc.wait_program(1, WAIT_S)
        return int(cnc.alarms().active[0].sequence)


def alarm_state(service: ServiceProcess, sequence: int) -> AlarmState:
    with CncClient(service.endpoint, timeout_s=WAIT_S) as cnc:
        [alarm] = [a for a in cnc.alarms(history=True).history if a.sequence == sequence]
        return alarm.state


async def subscribe(client: Client, notifier: Any, type_id: ua.NodeId,
                    also: tuple[ua.QualifiedName, ...] = ()) -> tuple[Any, _Events]:
    """Events of ``type_id`` from ``notifier``; ``also``: fields asyncua's client does
    not select by itself (a property the nodeset declares without a value)."""
    events = _Events()
    subscription = await client.create_subscription(20, events)
    evfilter = await get_filter_from_event_type([client.get_node(type_id)])
    for name in also:
        evfilter.SelectClauses.append(ua.SimpleAttributeOperand(
            TypeDefinitionId=type_id, BrowsePath=[name], AttributeId=ua.AttributeIds.Value))
    await subscription.subscribe_events(notifier, type_id, evfilter=evfilter)
    return subscription, events


async def test_a_bad_programs_alarm_is_an_event_that_acknowledges_as_cnc_alarms_ack(
        machine: Running) -> None:
    service, url = machine
    async with connected(url) as client:
        cnc_ns = await client.get_namespace_index(CNC_URI)
        mt_ns = await client.get_namespace_index(MT_URI)
        messages = await child(await machine_node(client), "Notification", "Messages")
        subscription, events = await subscribe(client, client.nodes.server,
                                               ua.NodeId(1006, cnc_ns))  # CncAlarmType
        alerts_sub, alerts = await subscribe(client, messages, ua.NodeId(39, mt_ns),  # AlertType
                                             (ua.QualifiedName("ErrorCode", mt_ns),))
        interface = await client.nodes.objects.get_child(f"{cnc_ns}:CncInterface")
        interface_sub, interface_events = await subscribe(client, interface,
                                                          ua.NodeId(1006, cnc_ns))
        sequence = await asyncio.to_thread(fail, service)
        raised = await events.wait(lambda e: e.ConditionName == f"Alarm{sequence}")
        assert (raised.AlarmIdentifier, raised.Severity, raised.SourceName) == (
            "20008", 800, "Channel1")
        assert raised.Message.Text.startswith("bad.nc:2:1: ")
        assert raised.Retain is True
        alert = await alerts.wait(lambda e: e.ConditionName == f"Alarm{sequence}")
        assert (alert.ErrorCode, alert.Severity) == ("20008", 800)
        from_interface = await interface_events.wait(
            lambda e: e.ConditionName == f"Alarm{sequence}")
        assert from_interface.AlarmIdentifier == "20008"

        seen = len(events.seen)
        condition = client.get_node(raised.NodeId)
        await condition.call_method(ACKNOWLEDGE, ua.Variant(raised.EventId, ua.VariantType.ByteString),
                                    ua.LocalizedText("seen"))
        acked = await events.wait(lambda e: e.ConditionName == f"Alarm{sequence}", seen)
        assert acked.AckedState.Text == "Acknowledged"
        assert await asyncio.to_thread(alarm_state, service, sequence) == AlarmState.ACKNOWLEDGED
        with pytest.raises(ua.UaStatusCodeError) as again:  # acknowledged already
            await condition.call_method(ACKNOWLEDGE, ua.Variant(raised.EventId,
                                                                ua.VariantType.ByteString),
                                        ua.LocalizedText("again"))
        assert again.value.code == ua.StatusCodes.BadConditionBranchAlreadyAcked
        await subscription.delete()
        await alerts_sub.delete()
        await interface_sub.delete()


async def test_condition_refresh_sends_the_active_alarms_again(machine: Running) -> None:
    service, url = machine
    async with connected(url) as client:
        cnc_ns = await client.get_namespace_index(CNC_URI)
        subscription, events = await subscribe(client, client.nodes.server,
                                               ua.NodeId(1006, cnc_ns))
        sequence = await asyncio.to_thread(fail, service, "refresh.nc")
        await events.wait(lambda e: e.ConditionName == f"Alarm{sequence}")  # raised
        events_before = len(events.seen)
        all_events = _Events()
        everything = await client.create_subscription(20, all_events)
        await everything.subscribe_events(client.nodes.server, [
            ua.NodeId(ua.ObjectIds.RefreshStartEventType),
            ua.NodeId(ua.ObjectIds.RefreshEndEventType), ua.NodeId(1006, cnc_ns)])
        condition_type = client.get_node(ua.NodeId(ua.ObjectIds.ConditionType))
        await condition_type.call_method(REFRESH, ua.Variant(everything.subscription_id,
                                                             ua.VariantType.UInt32))
        start = await all_events.wait(
            lambda e: e.EventType == ua.NodeId(ua.ObjectIds.RefreshStartEventType))
        again = await all_events.wait(lambda e: (e.Message.Text or "").startswith("refresh.nc:2:1"))
        end = await all_events.wait(
            lambda e: e.EventType == ua.NodeId(ua.ObjectIds.RefreshEndEventType))
        order = [all_events.seen.index(e) for e in (start, again, end)]
        assert order == sorted(order)
        assert again.Retain is True and f"Alarm{sequence}" == again.ConditionName
        assert len(events.seen) == events_before  # the other subscription got none
        await subscription.delete()
        await everything.delete()


async def test_a_monitors_acknowledge_is_refused_and_changes_nothing(monitored: Running) -> None:
    service, url = monitored
    async with connected(url) as client:
        cnc_ns = await client.get_namespace_index(CNC_URI)
        subscription, events = await subscribe(client, client.nodes.server,
                                               ua.NodeId(1006, cnc_ns))
        sequence = await asyncio.to_thread(fail, service)
        raised = await events.wait(lambda e: e.ConditionName == f"Alarm{sequence}")
        with pytest.raises(ua.UaStatusCodeError) as refused:
            await client.get_node(raised.NodeId).call_method(
                ACKNOWLEDGE, ua.Variant(raised.EventId, ua.VariantType.ByteString),
                ua.LocalizedText("no"))
        assert refused.value.code == ua.StatusCodes.BadUserAccessDenied
        assert await asyncio.to_thread(alarm_state, service, sequence) == AlarmState.ACTIVE
        await subscription.delete()


async def test_reset_clears_the_condition_and_its_node_goes(machine: Running) -> None:
    service, url = machine
    async with connected(url) as client:
        cnc_ns = await client.get_namespace_index(CNC_URI)
        messages = await child(await machine_node(client), "Notification", "Messages")
        subscription, events = await subscribe(client, client.nodes.server,
                                               ua.NodeId(1006, cnc_ns))
        sequence = await asyncio.to_thread(fail, service, "reset.nc")
        name = f"Alarm{sequence}"
        raised = await events.wait(lambda e: e.ConditionName == name)
        assert name in [(await c.read_browse_name()).Name for c in await messages.get_children()]
        with CncClient(service.endpoint, timeout_s=WAIT_S) as cnc:
            cnc.reset(1)
        cleared = await events.wait(lambda e: e.ConditionName == name and not e.Retain)
        assert cleared.ActiveState.Text == "Inactive" and cleared.NodeId == raised.NodeId
        assert name not in [(await c.read_browse_name()).Name
                            for c in await messages.get_children()]
        with pytest.raises(ua.UaStatusCodeError) as gone:
            await client.get_node(raised.NodeId).call_method(
                ACKNOWLEDGE, ua.Variant(raised.EventId, ua.VariantType.ByteString),
                ua.LocalizedText("late"))
        assert gone.value.code == ua.StatusCodes.BadNodeIdInvalid  # its node is gone
        assert "alarm events" not in service.log_text  # nothing failed on the way
        await subscription.delete()


async def status_of(call: Any) -> int:
    """The status code a method call is refused with (0: it was not)."""
    try:
        await call
    except ua.UaStatusCodeError as refused:
        return int(refused.code)
    return 0


async def test_bad_method_arguments_get_their_status_and_change_nothing(
        machine: Running) -> None:
    service, url = machine
    async with connected(url) as client:
        cnc_ns = await client.get_namespace_index(CNC_URI)
        subscription, events = await subscribe(client, client.nodes.server,
                                               ua.NodeId(1006, cnc_ns))
        sequence = await asyncio.to_thread(fail, service, "args.nc")
        raised = await events.wait(lambda e: e.ConditionName == f"Alarm{sequence}")
        condition = client.get_node(raised.NodeId)
        event_id = ua.Variant(raised.EventId, ua.VariantType.ByteString)
        comment = ua.LocalizedText("x")
        assert await status_of(condition.call_method(ACKNOWLEDGE, event_id)) == (
            ua.StatusCodes.BadArgumentsMissing)
        assert await status_of(condition.call_method(
            ACKNOWLEDGE, ua.Variant(b"no such event", ua.VariantType.ByteString), comment)) == (
            ua.StatusCodes.BadEventIdUnknown)
        assert await status_of(condition.call_method(ACKNOWLEDGE, "text", comment)) == (
            ua.StatusCodes.BadInvalidArgument)
        assert await status_of(client.nodes.server.call_method(ACKNOWLEDGE, event_id,
                                                               comment)) == (
            ua.StatusCodes.BadNodeIdUnknown)  # the Server object is no condition
        condition_type = client.get_node(ua.NodeId(ua.ObjectIds.ConditionType))
        assert await status_of(condition_type.call_method(
            REFRESH, ua.Variant(987654, ua.VariantType.UInt32))) == (
            ua.StatusCodes.BadSubscriptionIdInvalid)
        assert await asyncio.to_thread(alarm_state, service, sequence) == AlarmState.ACTIVE

        # ConditionRefresh2: the item asked for gets the events, another item none
        other = await subscription.subscribe_events(client.nodes.server,
                                                    ua.NodeId(1006, cnc_ns))
        before = len(events.seen)
        refresh2 = ua.NodeId(ua.ObjectIds.ConditionType_ConditionRefresh2)
        assert await status_of(condition_type.call_method(
            refresh2, ua.Variant(subscription.subscription_id, ua.VariantType.UInt32),
            ua.Variant(other, ua.VariantType.UInt32))) == 0
        again = await events.wait(lambda e: e.ConditionName == f"Alarm{sequence}", before)
        assert again.EventId == raised.EventId
        assert {e.server_handle for e in events.seen[before:]} == {other}
        await subscription.delete()
