"""The CncInterface (OPC 40502) instance under Objects: CncChannelList, CncAxisList and
CncSpindleList with one CncChannelType, CncAxisType, CncSpindleType per channel, axis
and spindle of the machine configuration; every mandatory member bound to the objects
(``cnc_members``). asyncua instantiates each type's mandatory members (its supertypes'
included); ``bind_members`` then binds every one of them, and fails at start when one is
left without a source, so that no member is ever served empty by omission."""

from __future__ import annotations

from typing import Any

from asyncua import Node, Server, ua

from . import cnc_members as members
from .binding import VariableBinder
from .linked_backend import LinkedBackend
from .nodesets import CNC_URI
from .sources import Source

#: The CNC nodeset's type ids (ns = the CNC namespace).
CNC_INTERFACE_TYPE, CHANNEL_LIST_TYPE, AXIS_LIST_TYPE, SPINDLE_LIST_TYPE = 1007, 1010, 1008, 1009
CHANNEL_TYPE, AXIS_TYPE, SPINDLE_TYPE = 1002, 1004, 1005
INTERFACE_NAME = "CncInterface"


async def build_cnc_interface(server: Server, binder: VariableBinder, backend: LinkedBackend,
                              vendor: str, version: str) -> Node:
    """Add the CncInterface with every channel, axis and spindle; returns its node.
    ``version``: the kernel's (VendorRevision)."""
    ns = await server.get_namespace_index(CNC_URI)
    objects = server.nodes.objects
    interface = await _instance(objects, ns, INTERFACE_NAME, CNC_INTERFACE_TYPE)
    for name, value in (("VendorName", vendor), ("VendorRevision", version),
                        ("Version", "1.0.0")):  # the CNC companion spec's version served
        await (await interface.get_child(f"{ns}:{name}")).write_value(value)
    channel_list = await interface.get_child(f"{ns}:CncChannelList")
    axis_list = await interface.get_child(f"{ns}:CncAxisList")
    spindle_list = await interface.get_child(f"{ns}:CncSpindleList")
    config = backend.kernel.config
    names = [a.name for c in config.channels for a in c.axes]
    unique = len(names) == len(set(names))
    for channel in config.channels:
        c = channel.id
        node = await _instance(channel_list, ns, f"Channel{c}", CHANNEL_TYPE)
        await (await node.get_child(f"{ns}:Id")).write_value(ua.Variant(c, ua.VariantType.UInt32))
        await bind_members(binder, node, ns, members.channel_members(c, bool(channel.axes)))
        await _positions(binder, node, ns, c, [(a.name, a.axis_type == "rotary")
                                                for a in channel.axes])
        for a, axis in enumerate(channel.axes, start=1):
            name = axis.name if unique else f"Ch{c}_{axis.name}"
            axis_node = await _instance(axis_list, ns, name, AXIS_TYPE)
            prefix, rotary = f"ch{c}.ax{a}.", axis.axis_type == "rotary"
            await bind_members(binder, axis_node, ns, members.axis_members(prefix, rotary))
            for member, parts in members.axis_positions(prefix, rotary).items():
                await bind_position(binder, axis_node, ns, member, parts)
            await _act_channel(axis_node, ns, node)
            await node.add_reference(axis_node, ua.ObjectIds.Organizes)
        spindle = await _instance(spindle_list, ns, f"Spindle{c}", SPINDLE_TYPE)
        await bind_members(binder, spindle, ns, members.spindle_members(c))
        await bind_position(binder, spindle, ns, "AnglePos", members.spindle_position(c))
        await _act_channel(spindle, ns, node)
        await node.add_reference(spindle, ua.ObjectIds.Organizes)
    return interface


async def _instance(parent: Node, ns: int, name: str, type_id: int) -> Node:
    """An instance of a CNC type under ``parent``: asyncua instantiates the type's
    members; the optional placeholders it copies too (``<CncAxis>``, ``<CncSpindle>``)
    are removed (they name where instances may go, OPC 10000-3 6.4.4.4.4)."""
    node = await parent.add_object(ns, name, ua.NodeId(type_id, ns))
    for child in await node.get_children():
        if (await child.read_browse_name()).Name.startswith("<"):
            await child.delete()
    return node


async def bind_members(binder: VariableBinder, node: Node, ns: int,
                       sources: dict[str, Source]) -> None:
    """Bind each member of ``node`` named in ``sources`` (``KeyError`` for a name the
    instance does not have)."""
    for name, source in sources.items():
        child = await node.get_child(f"{ns}:{name}")
        await binder.bind(child.nodeid, source)


async def bind_position(binder: VariableBinder, node: Node, ns: int, name: str,
                        parts: dict[str, Source]) -> None:
    """A CncPositionVariableType member: ActPos, CmdPos, RemDist bound, the variable
    itself their CncPositionDataType structure."""
    variable = await node.get_child(f"{ns}:{name}")
    await bind_members(binder, variable, ns, parts)
    struct = getattr(ua, "CncPositionDataType", None)  # made by asyncua from the nodeset
    objects = tuple(o for part in parts.values() for o in part.objects)
    convert = [part.value for part in parts.values()]
    counts = [len(part.objects) for part in parts.values()]

    def value(*raw: Any) -> Any:
        fields, k = [], 0
        for fn, n in zip(convert, counts):
            fields.append(fn(*raw[k:k + n]))
            k += n
        if struct is None:
            return fields[0]
        return struct(ActPos=fields[0], CmdPos=fields[1], RemDist=fields[2])

    variant = ua.VariantType.ExtensionObject if struct is not None else ua.VariantType.Double
    await binder.bind(variable.nodeid, Source(objects, value, variant,
                                              unit=parts["ActPos"].unit,
                                              limits=members.POSITION_RANGE))


async def _positions(binder: VariableBinder, channel: Node, ns: int, c: int,
                     axes: list[tuple[str, bool]]) -> None:
    """PosTcpBcs<X..C> (machine coordinates) and PosTcpWcs<X..C> (workpiece coordinates)
    of the channel: the channel's axis of that name (``axes``: name, rotary); an axis
    the channel does not have reads 0 (docs/opcua.md)."""
    names = [name for name, _ in axes]
    for coordinate in "XYZABC":
        for frame in ("Bcs", "Wcs"):
            name = f"PosTcp{frame}{coordinate}"
            if coordinate not in names:
                parts = members.fixed_position(f"channel {c} has no {coordinate} axis")
            else:
                a = names.index(coordinate)
                positions = members.axis_positions(f"ch{c}.ax{a + 1}.", axes[a][1])
                parts = positions["PosDirect" if frame == "Bcs" else "PosIndirect"]
            await bind_position(binder, channel, ns, name, parts)


async def _act_channel(node: Node, ns: int, channel: Node) -> None:
    """ActChannel of an axis or spindle: the node of its channel (fixed)."""
    child = await node.get_child(f"{ns}:ActChannel")
    await child.write_value(ua.Variant(channel.nodeid, ua.VariantType.NodeId))
