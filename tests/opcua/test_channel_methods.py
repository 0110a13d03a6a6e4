"""A channel's Start, Hold, Reset and SelectProgram as OPC UA methods in the twin's own
namespace (real service, virtual clock, asyncua's client): they do what ``cnc run`` /
``cnc hold`` / ``cnc resume`` / ``cnc reset`` do, the kernel's refusal is a status code,
a monitor gets BadUserAccessDenied and nothing happens (docs/opcua.md, "Methods")."""

from __future__ import annotations

from collections.abc import Iterator

import pytest
from asyncua import Client, Node, ua

from cnc_objects.clients import Client as CncClient
from cnc_objects.protocol.values import ChannelState
from cnc_objects.testing import ServiceProcess
from tests.support.opcua_machine import (
    WAIT_S,
    Changes,
    Running,
    child,
    connected,
    machine_node,
    serving_opcua,
)

OBJECTS_URI = "urn:cnc-objects:opcua"
SHORT = "G1 X10 F6000\nG1 X0\nM30\n"  # ends at once on the virtual clock
#: 100 minutes of virtual time at F1: long enough to hold, resume and reset in
LONG = "G1 X100 F1\nM30\n"
BAD = "G0 X1\nG1 X10\nM30\n"  # line 2: G1 without F, the channel ends in ERROR
ACTIVE, INTERRUPTED, RESET = 0, 1, 2  # MachineTool ChannelState (CncChannelStatus)


@pytest.fixture(scope="module")
def machine(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Running]:
    with serving_opcua(tmp_path_factory.mktemp("channel-methods")) as running:
        yield running


@pytest.fixture(scope="module")
def monitored(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Running]:
    """A service whose OPC UA sessions are monitors."""
    with serving_opcua(tmp_path_factory.mktemp("channel-methods-monitor"),
                       '[opcua]\nloopback_role = "monitor"\n') as running:
        yield running


async def channel_object(client: Client, channel: int = 1) -> tuple[Node, int]:
    """Machines/<machine>/CncObjects/Channel<c> and the twin's namespace index."""
    ns = await client.get_namespace_index(OBJECTS_URI)
    node = await (await machine_node(client)).get_child(
        [f"{ns}:CncObjects", f"{ns}:Channel{channel}"])
    return node, ns


async def watched_channel_state(client: Client) -> tuple[Node, Changes]:
    """MachineTool's Monitoring/Channel1/ChannelState, subscribed (20 ms): the node and
    the changes seen."""
    monitoring = await child(await machine_node(client), "Monitoring", "Channel1")
    channel_state = await child(monitoring, "ChannelState")
    changes = Changes()
    subscription = await client.create_subscription(20, changes)
    await subscription.subscribe_data_change([channel_state])
    return channel_state, changes


def store(service: ServiceProcess, name: str, text: str) -> None:
    """Reset channel 1 and put ``text`` in the program store as ``name`` (cnc upload)."""
    with CncClient(service.endpoint, timeout_s=WAIT_S) as cnc:
        cnc.reset(1)
        cnc.upload(name, text.encode())


def kernel_state(service: ServiceProcess) -> ChannelState:
    with CncClient(service.endpoint, timeout_s=WAIT_S) as cnc:
        return ChannelState(cnc.read("ch1.mc_active_state_r"))


async def call_status(node: Node, method: str, ns: int, *args: ua.Variant) -> int:
    """The status code of ``method`` called on ``node`` (Good: 0)."""
    request = ua.CallMethodRequest(ObjectId=node.nodeid,
                                   MethodId=(await node.get_child(f"{ns}:{method}")).nodeid,
                                   InputArguments=list(args))
    [result] = await node.session.call([request])
    return int(result.StatusCode.value)


async def test_the_methods_are_described_under_the_machine(machine: Running) -> None:
    async with connected(machine[1]) as client:
        node, ns = await channel_object(client)
        names = {(await c.read_browse_name()).Name for c in await node.get_children()}
        assert names == {"Start", "Hold", "Reset", "SelectProgram"}
        select = await node.get_child(f"{ns}:SelectProgram")
        [argument] = await (await select.get_child("0:InputArguments")).read_value()
        assert (argument.Name, argument.DataType) == ("Name", ua.NodeId(ua.ObjectIds.String))
        assert argument.Description.Text
        for name in names:
            description = await (await node.get_child(f"{ns}:{name}")).read_description()
            assert description.Text
        await channel_object(client, 2)  # every channel has its own


async def test_select_and_start_run_a_stored_program_to_its_end(machine: Running) -> None:
    service, url = machine
    store(service, "short.nc", SHORT)
    async with connected(url) as client:
        node, ns = await channel_object(client)
        program = await child(await machine_node(client), "Production", "ActiveProgram")
        name, state = await child(program, "Name"), await child(program, "State", "CurrentState")
        changes = Changes()
        subscription = await client.create_subscription(20, changes)
        await subscription.subscribe_data_change([name, state])
        await node.call_method(f"{ns}:SelectProgram", ua.Variant("short.nc"))
        await node.call_method(f"{ns}:Start")
        await changes.wait(name, lambda v: v == "short.nc")
        await changes.wait(state, lambda v: v.Text == "Ended")
        await subscription.delete()
    with CncClient(service.endpoint, timeout_s=WAIT_S) as cnc:
        assert cnc.read("ch1.mc_active_program_name_r") == "short.nc"


async def test_hold_stops_start_resumes_reset_ends(machine: Running) -> None:
    service, url = machine
    store(service, "long.nc", LONG)
    async with connected(url) as client:
        node, ns = await channel_object(client)
        channel_state, changes = await watched_channel_state(client)
        await changes.wait(channel_state, lambda v: v == RESET)
        await node.call_method(f"{ns}:SelectProgram", ua.Variant("long.nc"))
        await node.call_method(f"{ns}:Start")
        await changes.wait(channel_state, lambda v: v == ACTIVE)
        seen = len(changes.values[channel_state.nodeid])
        await node.call_method(f"{ns}:Hold")
        await changes.wait(channel_state, lambda v: v == INTERRUPTED)
        assert kernel_state(service) == ChannelState.HOLD
        changes.values[channel_state.nodeid] = changes.values[channel_state.nodeid][seen:]
        await node.call_method(f"{ns}:Start")  # resumes
        await changes.wait(channel_state, lambda v: v == ACTIVE)
        assert kernel_state(service) == ChannelState.ACTIVE
        await node.call_method(f"{ns}:Reset")
        changes.values[channel_state.nodeid] = []
        await changes.wait(channel_state, lambda v: v == RESET)
        assert kernel_state(service) == ChannelState.READY


async def test_start_without_a_ready_channel_is_bad_invalid_state(machine: Running) -> None:
    service, url = machine
    store(service, "long.nc", LONG)
    async with connected(url) as client:
        node, ns = await channel_object(client)
        await node.call_method(f"{ns}:SelectProgram", ua.Variant("long.nc"))
        await node.call_method(f"{ns}:Start")
        try:
            # a program runs: another selection is refused and changes nothing
            status = await call_status(node, "SelectProgram", ns, ua.Variant("short.nc"))
            assert status == ua.StatusCodes.BadInvalidState
            with CncClient(service.endpoint, timeout_s=WAIT_S) as cnc:
                assert cnc.read("ch1.mc_active_program_name_r") == "long.nc"
        finally:
            await node.call_method(f"{ns}:Reset")


async def test_start_in_error_is_bad_invalid_state_until_reset(machine: Running) -> None:
    service, url = machine
    store(service, "bad.nc", BAD)
    async with connected(url) as client:
        node, ns = await channel_object(client)
        channel_state, changes = await watched_channel_state(client)
        await node.call_method(f"{ns}:SelectProgram", ua.Variant("bad.nc"))
        await node.call_method(f"{ns}:Start")
        await changes.wait(channel_state, lambda v: v == INTERRUPTED)
        assert kernel_state(service) == ChannelState.ERROR
        assert await call_status(node, "Start", ns) == ua.StatusCodes.BadInvalidState
        assert kernel_state(service) == ChannelState.ERROR  # refused: nothing changed
        assert await call_status(node, "Reset", ns) == ua.StatusCodes.Good
        assert kernel_state(service) != ChannelState.ERROR


async def test_bad_arguments_are_refused(machine: Running) -> None:
    before = kernel_state(machine[0])
    async with connected(machine[1]) as client:
        node, ns = await channel_object(client)
        assert await call_status(node, "SelectProgram", ns) == ua.StatusCodes.BadArgumentsMissing
        assert await call_status(node, "SelectProgram", ns, ua.Variant(7, ua.VariantType.Int32)
                                 ) == ua.StatusCodes.BadTypeMismatch
        assert await call_status(node, "SelectProgram", ns, ua.Variant("")
                                 ) == ua.StatusCodes.BadInvalidArgument
        assert await call_status(node, "SelectProgram", ns, ua.Variant("x" * 10_000)
                                 ) == ua.StatusCodes.BadInvalidArgument
        assert await call_status(node, "SelectProgram", ns, ua.Variant("missing.nc")
                                 ) == ua.StatusCodes.BadNotFound
        assert await call_status(node, "SelectProgram", ns, ua.Variant("a"), ua.Variant("b")
                                 ) == ua.StatusCodes.BadTooManyArguments
        assert await call_status(node, "Start", ns, ua.Variant(True)
                                 ) == ua.StatusCodes.BadTooManyArguments
    assert kernel_state(machine[0]) == before != ChannelState.ACTIVE  # nothing started


async def test_a_monitor_is_refused_and_nothing_happens(monitored: Running) -> None:
    service, url = monitored
    store(service, "short.nc", SHORT)
    before = kernel_state(service)
    assert before != ChannelState.ACTIVE
    async with connected(url) as client:
        node, ns = await channel_object(client)
        for method, args in (("SelectProgram", [ua.Variant("short.nc")]), ("Start", []),
                             ("Hold", []), ("Reset", [])):
            status = await call_status(node, method, ns, *args)
            assert status == ua.StatusCodes.BadUserAccessDenied, method
    with CncClient(service.endpoint, timeout_s=WAIT_S) as cnc:
        assert ChannelState(cnc.read("ch1.mc_active_state_r")) == before  # nothing ran
        assert cnc.read("ch1.mc_active_program_name_r") != "short.nc"
