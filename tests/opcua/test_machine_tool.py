"""The MachineTool (OPC 40501-1) instance over OPC UA (real service, virtual clock,
asyncua's client): the tree as the umati sample servers show it, every Mandatory member
of every type definition on every instance, every variable readable, values that follow
the kernel (docs/opcua.md, "MachineTool (OPC 40501-1)")."""

from __future__ import annotations

from collections.abc import Iterator

import pytest
from asyncua import Client, Node, ua
from asyncua.common.ua_utils import get_node_supertypes

from cnc_objects.clients import Client as CncClient
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

MT_URI = "http://opcfoundation.org/UA/MachineTool/"
DI_URI = "http://opcfoundation.org/UA/DI/"
STOPS = "M3 S1000\nG1 X10 F600\nM0\nG1 X0\nM5\nM30\n"  # waits at M0 while the test looks
_MANDATORY = {ua.ObjectIds.ModellingRule_Mandatory}
_PLACEHOLDER = {ua.ObjectIds.ModellingRule_MandatoryPlaceholder}


@pytest.fixture(scope="module")
def machine(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[ServiceProcess, str]]:
    with serving_opcua(tmp_path_factory.mktemp("machine-tool")) as running:
        yield running


async def conformance_gaps(client: Client, root: Node) -> tuple[list[str], int]:
    """Every Mandatory member (of the type definition and its supertypes) that an
    instance under ``root`` lacks, and every MandatoryPlaceholder without an instance;
    and how many members were looked for."""
    gaps: list[str] = []
    checked = [0]
    declared: dict[ua.NodeId, list[tuple[str, int, ua.NodeId | None]]] = {}

    async def members(type_id: ua.NodeId) -> list[tuple[str, int, ua.NodeId | None]]:
        if type_id not in declared:
            found = []
            for supertype in await get_node_supertypes(client.get_node(type_id),
                                                       includeitself=True):
                for c in await supertype.get_children():
                    rules = await c.get_referenced_nodes(refs=ua.ObjectIds.HasModellingRule)
                    if rules and rules[0].nodeid.Identifier in _MANDATORY | _PLACEHOLDER:
                        found.append(((await c.read_browse_name()).Name,
                                      rules[0].nodeid.Identifier,
                                      await c.read_type_definition()))
            declared[type_id] = found
        return declared[type_id]

    async def walk(node: Node, path: str) -> None:
        type_id = await node.read_type_definition()
        children = {(await c.read_browse_name()).Name: c for c in await node.get_children()}
        if type_id is not None and not type_id.is_null():
            for name, rule, member_type in await members(type_id):
                checked[0] += 1
                if rule in _MANDATORY and name not in children:
                    gaps.append(f"{path}: {name}")
                elif rule in _PLACEHOLDER:
                    typed = [await c.read_type_definition() for c in children.values()]
                    if member_type not in typed:
                        gaps.append(f"{path}: {name} (no instance)")
        for name, c in children.items():
            if await c.read_node_class() in (ua.NodeClass.Object, ua.NodeClass.Variable):
                await walk(c, f"{path}/{name}")

    await walk(root, (await root.read_browse_name()).Name)
    return gaps, checked[0]


async def variables(node: Node) -> list[Node]:
    """Every variable under ``node``."""
    found = []
    for c in await node.get_children():
        if await c.read_node_class() == ua.NodeClass.Variable:
            found.append(c)
        found += await variables(c)
    return found


async def test_the_tree_is_the_umati_sample_servers_one(machine: Running) -> None:
    async with connected(machine[1]) as client:
        node = await machine_node(client)
        assert (await node.read_browse_name()).Name == "cnc-objects"
        mt = await client.get_namespace_index(MT_URI)
        assert await node.read_type_definition() == ua.NodeId(13, mt)  # MachineToolType
        identity = await child(node, "Identification")
        assert (await (await child(identity, "Manufacturer")).read_value()).Text == "cnc-objects"
        assert await (await child(identity, "SoftwareRevision")).read_value()
        assert await (await child(identity, "SerialNumber")).read_value() == "cnc-objects"
        monitoring = await child(node, "Monitoring")
        names = {(await c.read_browse_name()).Name for c in await monitoring.get_children()}
        assert {"MachineTool", "Channel1", "Channel2", "Spindle1", "Spindle2"} <= names
        state = await child(node, "Production", "ActiveProgram", "State", "CurrentState")
        assert (await state.read_value()).Text == "Initializing"
        tool = await child(node, "Equipment", "Tools", "Ch1_T1")
        assert await (await child(tool, "ControlIdentifier1")).read_value() == 1
        assert await (await child(tool, "ToolLife", "CuttingTime", "IsCountingUp")).read_value()
        await child(node, "Notification", "Messages")


async def test_every_mandatory_member_of_every_instance_is_there(machine: Running) -> None:
    async with connected(machine[1]) as client:
        gaps, checked = await conformance_gaps(client, await machine_node(client))
        assert gaps == []
        assert checked > 400  # 64 tools with 6 each (ToolLife included), the channels, ...


async def test_every_variable_reads_good_with_a_value(machine: Running) -> None:
    async with connected(machine[1]) as client:
        found = await variables(await machine_node(client))
        assert len(found) > 100
        values = []
        for k in range(0, len(found), 500):  # a Read of at most 500 nodes
            values += await client.read_attributes(found[k:k + 500])
        bad = [(v.nodeid.to_string(), d.StatusCode) for v, d in zip(found, values)
               if not d.StatusCode.is_good() or d.Value is None or d.Value.Value is None]
        assert bad == []


async def test_values_follow_a_running_program_and_the_overrides(machine: Running) -> None:
    service, url = machine
    async with connected(url) as client:
        node = await machine_node(client)
        program = await child(node, "Production", "ActiveProgram")
        name = await child(program, "Name")
        state = await child(program, "State", "CurrentState")
        operation_mode = await child(node, "Monitoring", "MachineTool", "OperationMode")
        channel = await child(node, "Monitoring", "Channel1")
        channel_state = await child(channel, "ChannelState")
        channel_mode, feed = await child(channel, "ChannelMode"), await child(channel, "FeedOverride")
        rotating = await child(node, "Monitoring", "Spindle1", "IsRotating")
        tool_name = await child(node, "Equipment", "Tools", "Ch1_T3", "Name")
        watched = [name, state, operation_mode, channel_state, channel_mode, feed, rotating,
                   tool_name]
        changes = Changes()
        subscription = await client.create_subscription(20, changes)
        await subscription.subscribe_data_change(watched)
        with CncClient(service.endpoint, timeout_s=WAIT_S) as cnc:
            cnc.reset(1)
            cnc.upload("stops.nc", STOPS.encode())
            cnc.run_program("stops.nc", 1)  # stays ACTIVE at its M0 until START
            await changes.wait(name, lambda v: v == "stops.nc")
            await changes.wait(state, lambda v: v.Text == "Running")
            await changes.wait(channel_state, lambda v: v == 0)  # Active
            await changes.wait(channel_mode, lambda v: v == 0)  # Automatic
            await changes.wait(operation_mode, lambda v: v == 1)  # Automatic
            await changes.wait(rotating, lambda v: v is True)  # M3 S1000
            cnc.write("ch1.mc_command_feed_override_w", 420)  # 42.0 %
            await changes.wait(feed, lambda v: abs(v - 42.0) < 1e-9)
            cnc.write("ch1.wz[3].name", "drill 6")
            await changes.wait(tool_name, lambda v: v == "drill 6")
            cnc.start(1)  # on to M5 and M30
            await changes.wait(state, lambda v: v.Text == "Ended")
            await changes.wait(rotating, lambda v: v is False)
            await changes.wait(channel_state, lambda v: v == 2)  # Reset (READY)
            cnc.write("ch1.mc_command_feed_override_w", 1000)
        await subscription.delete()


async def test_the_machine_tool_variables_are_read_only(machine: Running) -> None:
    """The overrides are written through the CncInterface (CmdOverride); a write of the
    MachineTool's FeedOverride is refused and changes nothing."""
    async with connected(machine[1]) as client:
        feed = await child(await machine_node(client), "Monitoring", "Channel1", "FeedOverride")
        before = await feed.read_value()
        with pytest.raises(ua.UaStatusCodeError) as refused:
            await feed.write_value(ua.DataValue(ua.Variant(12.0, ua.VariantType.Double)))
        assert refused.value.code == ua.StatusCodes.BadNotWritable
        assert await feed.read_value() == before
