"""The CncInterface (OPC 40502) over asyncua's client: the tree, every mandatory member
of every instance (a conformance walk over the type definitions), every value Good."""

from __future__ import annotations

from asyncua import Client, Node, ua

from cnc_objects.testing import serving
from tests.opcua.conftest import OPCUA_ANY_PORT, OPCUA_START_S, cnc_node, opcua_url

MANDATORY = ua.NodeId(ua.ObjectIds.ModellingRule_Mandatory)
_FORWARD, _INVERSE = ua.BrowseDirection.Forward, ua.BrowseDirection.Inverse


async def test_the_tree_has_every_channel_axis_and_spindle(ua_client: Client) -> None:
    lists = {}
    for name in ("CncChannelList", "CncAxisList", "CncSpindleList"):
        node = await cnc_node(ua_client, "CncInterface", name)
        lists[name] = sorted([(await c.read_browse_name()).Name
                              for c in await node.get_children()])
    # the default machine: two channels of X Y Z, a spindle each
    assert lists["CncChannelList"] == ["Channel1", "Channel2"]
    assert lists["CncAxisList"] == ["Ch1_X", "Ch1_Y", "Ch1_Z", "Ch2_X", "Ch2_Y", "Ch2_Z"]
    assert lists["CncSpindleList"] == ["Spindle1", "Spindle2"]


class _Types:
    """The mandatory members of a type and its supertypes, by browse name (cached)."""

    def __init__(self, client: Client) -> None:
        self.client = client
        self._known: dict[ua.NodeId, set[tuple[int, str]]] = {}

    async def mandatory(self, type_node: Node) -> set[tuple[int, str]]:
        known = self._known.get(type_node.nodeid)
        if known is not None:
            return known
        names: set[tuple[int, str]] = set()
        refs = await type_node.get_references(
            ua.ObjectIds.HierarchicalReferences, _FORWARD, ua.NodeClass.Unspecified, True)
        for ref in refs:
            if ref.ReferenceTypeId == ua.NodeId(ua.ObjectIds.HasSubtype):
                continue
            rule = await self.client.get_node(ref.NodeId).get_referenced_nodes(
                ua.ObjectIds.HasModellingRule, _FORWARD)
            if rule and rule[0].nodeid == MANDATORY:
                names.add((ref.BrowseName.NamespaceIndex, ref.BrowseName.Name))
        supertypes = await type_node.get_referenced_nodes(ua.ObjectIds.HasSubtype, _INVERSE)
        if supertypes:
            names |= await self.mandatory(supertypes[0])
        self._known[type_node.nodeid] = names
        return names


def _key(name: ua.QualifiedName) -> tuple[int, str]:
    return name.NamespaceIndex, name.Name


async def _walk(node: Node, path: str, types: _Types, missing: list[str],
                variables: list[Node]) -> None:
    """Check ``node``'s mandatory members, then its children's."""
    children = await node.get_children()
    names = {_key(await c.read_browse_name()) for c in children}
    type_definition = await node.read_type_definition()
    if type_definition is not None:
        types_node = types.client.get_node(type_definition)
        for name in await types.mandatory(types_node) - names:
            missing.append(f"{path}/{name[1]}")
    for child in children:
        child_class = await child.read_node_class()
        if child_class == ua.NodeClass.Variable:
            variables.append(child)
        if child_class in (ua.NodeClass.Object, ua.NodeClass.Variable):
            name = (await child.read_browse_name()).Name
            await _walk(child, f"{path}/{name}", types, missing, variables)


async def test_every_instance_has_every_mandatory_member_and_reads_good(
        ua_client: Client) -> None:
    interface = await cnc_node(ua_client, "CncInterface")
    missing: list[str] = []
    variables: list[Node] = []
    await _walk(interface, "CncInterface", _Types(ua_client), missing, variables)
    assert missing == []
    assert len(variables) > 500  # 2 channels, 6 axes, 2 spindles and their members
    results = await ua_client.uaclient.read_attributes(
        [v.nodeid for v in variables], ua.AttributeIds.Value)
    bad = [v.nodeid.to_string() for v, r in zip(variables, results) if not r.StatusCode.is_good()]
    assert bad == []


async def test_values_have_their_engineering_units(ua_client: Client) -> None:
    ns = await ua_client.get_namespace_index("http://opcfoundation.org/UA/CNC")
    channel = await cnc_node(ua_client, "CncInterface", "CncChannelList", "Channel1")
    override = await channel.get_child(f"{ns}:ActOverride")
    units = await (await override.get_child("0:EngineeringUnits")).read_value()
    assert (units.DisplayName.Text, units.UnitId) == ("%", 20529)  # UNECE P1
    eu_range = await (await override.get_child("0:EURange")).read_value()
    assert (eu_range.Low, eu_range.High) == (0.0, 150.0)
    assert await override.read_value() == 100.0
    feed = await channel.get_child(f"{ns}:ActFeedrate")
    units = await (await feed.get_child("0:EngineeringUnits")).read_value()
    assert units.DisplayName.Text == "mm/min"


async def test_every_analog_item_has_units_and_a_range(ua_client: Client) -> None:
    interface = await cnc_node(ua_client, "CncInterface")
    variables: list[Node] = []
    await _walk(interface, "CncInterface", _Types(ua_client), [], variables)
    analog = ua.NodeId(ua.ObjectIds.AnalogItemType)
    checked, lacking = 0, []
    for variable in variables:
        if await variable.read_type_definition() != analog:
            continue
        checked += 1
        path = (await variable.read_browse_name()).Name
        units = await (await variable.get_child("0:EngineeringUnits")).read_value()
        eu_range = await (await variable.get_child("0:EURange")).read_value()
        if not isinstance(units, ua.EUInformation) or not isinstance(eu_range, ua.Range):
            lacking.append(path)
    assert checked > 50  # feeds, overrides, speeds, drive figures of every instance
    assert lacking == [], sorted(set(lacking))


async def test_a_rotary_axis_is_in_degrees() -> None:
    with serving("--machine", "five-axis-ac", *OPCUA_ANY_PORT,
                 timeout_s=OPCUA_START_S) as service:
        async with Client(opcua_url(service), timeout=30) as client:
            ns = await client.get_namespace_index("http://opcfoundation.org/UA/CNC")
            channel = await cnc_node(client, "CncInterface", "CncChannelList", "Channel1")
            units = {}
            for name in ("PosTcpBcsA", "PosTcpWcsC", "PosTcpBcsX", "PosTcpBcsB"):
                position = await channel.get_child(f"{ns}:{name}")
                act = await position.get_child(f"{ns}:ActPos")
                eu = await (await act.get_child("0:EngineeringUnits")).read_value()
                units[name] = eu.DisplayName.Text
    # the machine's A and C are rotary; it has no B: that position reads 0 mm
    assert units == {"PosTcpBcsA": "deg", "PosTcpWcsC": "deg", "PosTcpBcsX": "mm",
                     "PosTcpBcsB": "mm"}
