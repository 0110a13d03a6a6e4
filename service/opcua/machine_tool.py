"""The MachineTool (OPC 40501-1) instance under Objects/Machines, as the umati sample
servers populate it: Identification, Monitoring (the machine, a ChannelMonitoring per
channel, a SpindleMonitoring per spindle), Production/ActiveProgram, Equipment/Tools (a
ToolType per tool list row, with its cutting time as ToolLife) and Notification/Messages
(where the alarms arrive as events, ``alarm_events``).

asyncua instantiates each type's Mandatory members (its supertypes' included); the
Optional members the umati servers show are added from their declarations in the type
(``add_member``). Every variable is then bound to the objects (``machine_tool_members``,
through the core's ``VariableBinder``); ``check_bound`` fails at start when one is left
without a value, so that no member is ever served empty by omission.
"""

from __future__ import annotations

from asyncua import Node, Server, ua
from asyncua.common.instantiate_util import _instantiate_node
from asyncua.common.ua_utils import get_node_supertypes

from . import machine_tool_members as members
from .binding import VariableBinder
from .linked_backend import LinkedBackend
from .nodesets import MACHINE_TOOL_URI
from .sources import Source
from .values import eu_information

MACHINERY_URI = "http://opcfoundation.org/UA/Machinery/"
DI_URI = "http://opcfoundation.org/UA/DI/"
MACHINES_FOLDER = 1001  # Machinery's Objects/Machines (ns = Machinery)
#: MachineTool nodeset type ids (ns = MachineTool)
MACHINE_TOOL_TYPE, CHANNEL_MONITORING_TYPE, SPINDLE_MONITORING_TYPE = 13, 16, 22
TOOL_TYPE, PROGRAM_STATE_MACHINE_TYPE = 50, 15


async def build_machine_tool(server: Server, binder: VariableBinder, backend: LinkedBackend,
                             vendor: str, product_uri: str) -> Node:
    """Add the MachineTool instance of this service (named as its machine configuration)
    under Objects/Machines; returns its node."""
    ns = await server.get_namespace_index(MACHINE_TOOL_URI)
    di = await server.get_namespace_index(DI_URI)
    config = backend.kernel.config
    machines = server.get_node(ua.NodeId(MACHINES_FOLDER,
                                         await server.get_namespace_index(MACHINERY_URI)))
    machine = await machines.add_object(ns, config.name, ua.NodeId(MACHINE_TOOL_TYPE, ns),
                                        instantiate_optional=False)
    builder = _Builder(server, binder, ns)

    identity = await machine.get_child(f"{di}:Identification")
    for name in ("Model", "SoftwareRevision", "ProductCode", "YearOfConstruction"):
        await builder.add_member(identity, name)
    await builder.bind(identity, members.identification(vendor, config.name, product_uri))

    monitoring = await machine.get_child(f"{ns}:Monitoring")
    overall = await monitoring.get_child(f"{ns}:MachineTool")
    await builder.add_member(overall, "PowerOnDuration")
    await builder.bind(overall, members.machine_monitoring())

    production = await machine.get_child(f"{ns}:Production")
    program = await production.get_child(f"{ns}:ActiveProgram")
    state_ids = await _program_state_ids(server, ns)
    sources = members.active_program(1, state_ids)
    state = await program.get_child([f"{ns}:State", "0:CurrentState"])
    await builder.bind(program, {k: sources[k] for k in ("Name", "NumberInList")})
    await binder.bind(state.nodeid, sources["CurrentState"])
    await builder.bind(state, {k: sources[k] for k in ("Id", "Number")})

    equipment = await machine.get_child(f"{ns}:Equipment")
    tools = await builder.add_member(equipment, "Tools")
    notification = await machine.get_child(f"{ns}:Notification")
    await builder.add_member(notification, "Messages")

    for channel in config.channels:
        c = channel.id
        node = await monitoring.add_object(ns, f"Channel{c}",
                                           ua.NodeId(CHANNEL_MONITORING_TYPE, ns),
                                           instantiate_optional=False)
        await builder.add_member(node, "RapidOverride")
        await builder.bind(node, members.channel_monitoring(c))
        spindle = await monitoring.add_object(ns, f"Spindle{c}",
                                              ua.NodeId(SPINDLE_MONITORING_TYPE, ns),
                                              instantiate_optional=False)
        await builder.add_member(spindle, "Override")
        await builder.bind(spindle, members.spindle_monitoring(c))
        for i in range(1, config.tool_entries + 1):
            await builder.tool(tools, c, i, len(config.channels) > 1)
    await check_bound(machine, binder)
    return machine


class _Builder:
    """Adds optional members from their declarations and binds members by name."""

    def __init__(self, server: Server, binder: VariableBinder, ns: int) -> None:
        self.server, self.binder, self.ns = server, binder, ns
        #: (type, member name) -> the declaring type: 64 tools ask the same questions
        self._declaring: dict[tuple[ua.NodeId, str], Node] = {}
        self._declarations: dict[ua.NodeId, list[ua.ReferenceDescription]] = {}

    async def add_member(self, node: Node, name: str, recursive: bool = True) -> Node:
        """Add ``node``'s optional member ``name`` as its type (or a supertype) declares
        it (without its children unless ``recursive``)."""
        type_id = await node.read_type_definition()
        known = self._declaring.get((type_id, name))
        type_node = self.server.get_node(type_id)
        for declaring in ([known] if known is not None else
                          await get_node_supertypes(type_node, includeitself=True)):
            found = await self.instantiate(node, declaring, name, recursive=recursive)
            if found is not None:
                self._declaring[(type_id, name)] = declaring
                return found
        raise KeyError(f"{name}: no member of {type_id.to_string()}")

    async def instantiate(self, node: Node, declaring: Node, name: str,
                          as_name: str | None = None, recursive: bool = True) -> Node | None:
        """The member ``name`` that ``declaring`` declares, added to ``node`` (as
        ``as_name``): its type definition, data type and Mandatory children, by asyncua's
        own instantiation of a declaration (its public ``instantiate`` takes types
        only); the placeholders among them (``<ToolLifeEntry>``) left out. None when
        ``declaring`` has no such member."""
        if declaring.nodeid not in self._declarations:
            self._declarations[declaring.nodeid] = await declaring.get_children_descriptions()
        for rdesc in self._declarations[declaring.nodeid]:
            if rdesc.BrowseName.Name == name:
                bname = rdesc.BrowseName if as_name is None else ua.QualifiedName(as_name, self.ns)
                added = await _instantiate_node(
                    node.session, self.server.get_node(rdesc.NodeId), node.nodeid, rdesc,
                    ua.NodeId(NamespaceIndex=self.ns), bname, recursive=recursive,
                    instantiate_optional=False)
                member = self.server.get_node(added[0])
                for child in await member.get_children() if recursive else ():
                    if (await child.read_browse_name()).Name.startswith("<"):
                        await self.server.delete_nodes([child], recursive=True)
                return member
        return None

    async def bind(self, node: Node, sources: dict[str, Source]) -> None:
        """Bind each child of ``node`` named in ``sources`` (any namespace)."""
        children = {(await c.read_browse_name()).Name: c for c in await node.get_children()}
        for name, source in sources.items():
            await self.binder.bind(children[name].nodeid, source)

    async def tool(self, tools: Node, c: int, i: int, several: bool) -> None:
        """A ToolType for row ``i`` of channel ``c``'s tool list, with its ToolLife."""
        name = f"Ch{c}_T{i}" if several else f"T{i}"
        node = await tools.add_object(self.ns, name, ua.NodeId(TOOL_TYPE, self.ns),
                                      instantiate_optional=False)
        for member in ("Name", "Identifier"):
            await self.add_member(node, member)
        sources = members.tool(c, i)
        reason = sources.pop("ReasonForLocking")
        await self.bind(node, sources)
        await self.bind(await node.get_child(f"{self.ns}:Locked"), {"ReasonForLocking": reason})
        # its one child is the placeholder <ToolLifeEntry>: CuttingTime takes its place
        life = await self.add_member(node, "ToolLife", recursive=False)
        declared = await self.server.get_node(ua.NodeId(TOOL_TYPE, self.ns)).get_child(
            f"{self.ns}:ToolLife")
        cutting = await self.instantiate(life, declared, "<ToolLifeEntry>", "CuttingTime")
        assert cutting is not None  # the nodeset declares it
        await self.add_member(cutting, "LimitValue")
        life_sources = members.tool_life(c, i)
        units = await cutting.get_child(f"{self.ns}:EngineeringUnits")
        await units.write_value(eu_information("s"))
        await self.binder.bind(cutting.nodeid, life_sources.pop("CuttingTime"))
        await self.bind(cutting, life_sources)


async def _program_state_ids(server: Server, ns: int) -> tuple[ua.NodeId, ...]:
    """The state nodes of ProductionProgramStateMachineType, by number."""
    machine = server.get_node(ua.NodeId(PROGRAM_STATE_MACHINE_TYPE, ns))
    ids = []
    for name in members.PROGRAM_STATES:
        ids.append((await machine.get_child(f"{ns}:{name}")).nodeid)
    return tuple(ids)


async def check_bound(root: Node, binder: VariableBinder) -> None:
    """``RuntimeError`` naming every variable under ``root`` that is neither bound to
    the objects nor has a value of its own (a property the build wrote)."""
    missing: list[str] = []

    async def walk(node: Node, path: str) -> None:
        for child in await node.get_children():
            name = (await child.read_browse_name()).Name
            here = f"{path}/{name}"
            if await child.read_node_class() == ua.NodeClass.Variable:
                if child.nodeid not in binder.variables:
                    value = await child.read_data_value(raise_on_bad_status=False)
                    if value.Value is None or value.Value.Value is None:
                        missing.append(here)
            await walk(child, here)

    await walk(root, "")
    if missing:
        raise RuntimeError("MachineTool members without a value: " + ", ".join(missing))
