"""The catalog and its address rules (objects/catalog.py, addressing.py, model.py).

``build_objects`` over a two-channel, three-axis machine must give the documented ISG
addresses: channel in the group (``0x12130<CID>``), axis in the upper 16 bits of the
offset (``0x<AID>00xx``), the types, access and units of the ISG tables.
"""

from __future__ import annotations

import re

import pytest

from cnc_objects.objects.addressing import (
    LOGICAL_BIT,
    GroupBase,
    axis_offset,
    channel_group,
    index_based,
    split_axis_offset,
)
from cnc_objects.objects.catalog import (
    AREAS,
    PLC_GROUP,
    CatalogSizes,
    ChannelLayout,
    MachineLayout,
    Scope,
    build_objects,
    templates,
)
from cnc_objects.objects.model import Access, CncObject
from cnc_objects.objects.units import EngineeringScale
from cnc_objects.protocol.alarm_values import AlarmClass, AlarmState
from cnc_objects.protocol.constants import CncPort
from cnc_objects.protocol.datatypes import REAL64, SGN32, UNS16, UNS32, DataType
from cnc_objects.protocol.values import (
    ChannelMode,
    ChannelState,
    ContourBlockType,
    CoolantState,
    LinkState,
    ManualOperationMode,
    RapidOverrideMode,
    SpindleMode,
)
from cnc_objects.protocol.wait_reasons import WaitReason

PLC = CncPort.PLC

LAYOUT = MachineLayout(
    (ChannelLayout(1, 3), ChannelLayout(2, 3)), (1, 2, 3), hli_axes=(1, 2, 3, 11, 12, 13)
)
# two tool rows, G54 and G55, two alarm history slots: every area's tables appear
SIZES = CatalogSizes(tool_entries=2, zero_offset_groups=3, alarm_history=2)
TEMPLATES = templates(SIZES)


@pytest.fixture(scope="module")
def by_name() -> dict[str, CncObject]:
    return {o.name: o for o in build_objects(LAYOUT, SIZES)}


# (name, port, group, offset, type, access, unit)
DOCUMENTED = [
    ("ch2.ax3.actual_link_to_physical_axis", 551, 0x121302, 0x30017, UNS16, Access.READ, "-"),
    ("ch1.ax1.actual_link_to_physical_axis", 551, 0x121301, 0x10017, UNS16, Access.READ, "-"),
    ("ch1.ax2.requested_link_to_physical_axis", 551, 0x121301, 0x20016, UNS16, Access.READ, "-"),
    ("ch1.ax1.link_state", 551, 0x121301, 0x10018, UNS32, Access.READ, "-"),
    ("ch2.ax2.link_state", 551, 0x121302, 0x20018, UNS32, Access.READ, "-"),
    ("ch1.dist_prog_start", 551, 0x121301, 0x56, REAL64, Access.READ, "0.1 um"),
    ("ch2.dist_prog_start", 551, 0x121302, 0x56, REAL64, Access.READ, "0.1 um"),
    ("ch1.mc_command_execution_mode_w", 553, 0x120101, 0x3F, SGN32, Access.WRITE, "-"),
    ("ch1.mc_command_execution_mode_r", 553, 0x120101, 0x40, SGN32, Access.READ, "-"),
    ("ch1.mc_active_execution_mode_r", 553, 0x120101, 0x41, SGN32, Access.READ, "-"),
    ("ch2.mc_command_execution_mode_w", 553, 0x120102, 0x3F, SGN32, Access.WRITE, "-"),
    ("ch1.mc_command_feed_override_w", 553, 0x120101, 0x09, UNS16, Access.WRITE, "0.1 %"),
    ("ch1.mc_command_feed_override_r", 553, 0x120101, 0x0A, UNS16, Access.READ, "0.1 %"),
    ("ch1.mc_active_feed_override_r", 553, 0x120101, 0x0C, UNS16, Access.READ, "0.1 %"),
    ("ch2.mc_active_feed_override_r", 553, 0x120102, 0x0C, UNS16, Access.READ, "0.1 %"),
    ("ax2.command_position_acs", 553, 0x120200, 0x20002, SGN32, Access.READ, "0.1 um"),
    ("ax3.actual_position_acs", 553, 0x120200, 0x30003, SGN32, Access.READ, "0.1 um"),
]


@pytest.mark.parametrize(
    ("name", "port", "group", "offset", "dtype", "access", "unit"),
    DOCUMENTED,
    ids=[d[0] for d in DOCUMENTED],
)
def test_documented_addresses(
    by_name: dict[str, CncObject],
    name: str,
    port: int,
    group: int,
    offset: int,
    dtype: DataType,
    access: Access,
    unit: str,
) -> None:
    obj = by_name[name]
    assert (obj.port, obj.group, obj.offset) == (port, group, offset)
    assert obj.dtype is dtype
    assert obj.access is access
    assert obj.unit == unit
    assert obj.length == dtype.size


def test_channel_axis_objects_know_their_channel_and_axis(by_name: dict[str, CncObject]) -> None:
    obj = by_name["ch2.ax3.actual_link_to_physical_axis"]
    assert (obj.element, obj.channel, obj.axis) == ("actual_link_to_physical_axis", 2, 3)
    channel = by_name["ch1.dist_prog_start"]
    assert (channel.element, channel.channel, channel.axis) == ("dist_prog_start", 1, 0)
    drive = by_name["ax3.actual_position_acs"]
    assert (drive.channel, drive.axis) == (0, 3)


def test_platform_objects_have_plain_names(by_name: dict[str, CncObject]) -> None:
    version = by_name["cnc_version_r"]
    assert (version.port, version.channel, version.axis) == (553, 0, 0)
    assert version.group == GroupBase.COM_CHANNEL


def test_names_are_unique() -> None:
    names = [o.name for o in build_objects(LAYOUT, SIZES)]
    assert len(names) == len(set(names))
    lowered = [n.lower() for n in names]
    assert len(lowered) == len(set(lowered))


def test_addresses_are_unique() -> None:
    addresses = [(o.port, o.group, o.offset) for o in build_objects(LAYOUT, SIZES)]
    assert len(addresses) == len(set(addresses))


def _scope(obj) -> Scope:
    """The scope an instance was made for, from its name, channel and axis."""
    if obj.name.startswith("gpCh[") and ".bahn_state.coord_r[" in obj.name:
        return Scope.PLC_CHANNEL_AXIS
    if obj.name.startswith("gpCh["):
        return Scope.PLC_CHANNEL
    if obj.name.startswith("pMC["):
        return Scope.PLC_MC
    if obj.name.startswith("gpAx["):
        return Scope.PLC_AXIS
    if obj.channel:
        return Scope.CHANNEL_AXIS if obj.axis else Scope.CHANNEL
    return Scope.PHYSICAL_AXIS if obj.axis else Scope.PLATFORM


def test_every_template_is_instantiated_once_per_scope_member() -> None:
    objects = build_objects(LAYOUT, SIZES)
    expected = {
        Scope.PLATFORM: 1,
        Scope.PHYSICAL_AXIS: len(LAYOUT.physical_axes),
        Scope.CHANNEL: len(LAYOUT.channels),
        Scope.CHANNEL_AXIS: sum(c.axis_count for c in LAYOUT.channels),
        Scope.PLC_CHANNEL: len(LAYOUT.channels),
        Scope.PLC_MC: len(LAYOUT.channels),
        Scope.PLC_AXIS: len(LAYOUT.hli_axes),
        Scope.PLC_CHANNEL_AXIS: sum(c.axis_count for c in LAYOUT.channels),
    }
    for template in TEMPLATES:
        count = sum(
            1 for o in objects if o.element == template.element and _scope(o) == template.scope
        )
        assert count == expected[template.scope], template.element
    assert len(objects) == sum(expected[t.scope] for t in TEMPLATES)


def test_the_areas_are_one_list_and_sizes_size_their_tables() -> None:
    assert TEMPLATES == tuple(t for area in AREAS for t in area(SIZES))
    fixed = {t.element for t in templates()}
    sized = {t.element for t in TEMPLATES} - fixed
    assert "wz[2].radius" in sized and "np_grp[2].v" in sized
    assert "alarm_history[2].id" in sized and "wz[3].radius" not in sized


def test_every_object_follows_the_address_rules() -> None:
    templates = {(t.element, t.scope): t for t in TEMPLATES}
    assert len(templates) == len(TEMPLATES), "an element name repeats within one scope"
    for obj in build_objects(LAYOUT, SIZES):
        t = templates[obj.element, _scope(obj)]
        assert obj.port == PLC or obj.group & LOGICAL_BIT, obj.name
        assert obj.port == t.port and obj.dtype is t.dtype and obj.access is t.access
        match t.scope:
            case Scope.PLATFORM:
                assert obj.name == t.element
                assert (obj.group, obj.offset) == (t.group_base, t.offset)
            case Scope.PHYSICAL_AXIS:
                assert obj.name == f"ax{obj.axis}.{t.element}"
                assert (obj.group, obj.offset) == (t.group_base, axis_offset(obj.axis, t.offset))
            case Scope.CHANNEL:
                assert obj.name == f"ch{obj.channel}.{t.element}"
                assert (obj.group, obj.offset) == (t.group_base + obj.channel, t.offset)
            case Scope.CHANNEL_AXIS:
                assert obj.name == f"ch{obj.channel}.ax{obj.axis}.{t.element}"
                assert obj.group == t.group_base + obj.channel
                assert split_axis_offset(obj.offset) == (obj.axis, t.offset)
            case Scope.PLC_CHANNEL:  # gpCh[i]: i = position of the channel, from 0
                i = [c.channel_id for c in LAYOUT.channels].index(obj.channel)
                assert obj.name == f"gpCh[{i}].{t.element}"
                assert (obj.group, obj.offset) == (PLC_GROUP, 0x10000 + i * 0x1000 + t.offset)
            case Scope.PLC_MC:  # pMC[i]: the older name of the same per-channel block
                i = [c.channel_id for c in LAYOUT.channels].index(obj.channel)
                assert obj.name == f"pMC[{i}].{t.element}"
                assert (obj.group, obj.offset) == (PLC_GROUP, 0x10000 + i * 0x1000 + t.offset)
            case Scope.PLC_AXIS:  # gpAx[i]: i = slot of the axis number
                i = LAYOUT.hli_axes.index(obj.axis)
                assert obj.name == f"gpAx[{i}].{t.element}"
                assert (obj.group, obj.offset) == (PLC_GROUP, 0x80000 + i * 0x100 + t.offset)


def test_layout_drives_the_instances() -> None:
    layout = MachineLayout((ChannelLayout(3, 1),), (5,))
    names = {o.name for o in build_objects(layout)}
    assert "ch3.ax1.link_state" in names
    assert "ch3.ax2.link_state" not in names
    assert "ch1.dist_prog_start" not in names
    assert "ax5.actual_position_acs" in names
    assert "ax1.actual_position_acs" not in names
    by_name = {o.name: o for o in build_objects(layout)}
    assert by_name["ch3.ax1.link_state"].group == 0x121303
    assert by_name["ax5.link_to_logical_axis"].offset == 0x5000F


def test_empty_layout_keeps_platform_objects_only() -> None:
    objects = build_objects(MachineLayout((), ()), SIZES)
    platform = {t.element for t in TEMPLATES if t.scope is Scope.PLATFORM}
    assert {o.name for o in objects} == platform


# --------------------------------------------------------------------------- addressing


def test_channel_group() -> None:
    assert channel_group(GroupBase.GEO_INTERPOLATOR, 2) == 0x121302
    assert channel_group(GroupBase.COM_CHANNEL, 1) == 0x120101


@pytest.mark.parametrize(
    ("group", "logical_id", "index", "expected"),
    [
        (0x121302, 2, 2, 0x21302),
        (0x121301, 1, 1, 0x21301),
        (0x121305, 5, 1, 0x21301),  # logical channel 5 is the first configured channel
        (0x120102, 2, 1, 0x20101),
    ],
)
def test_index_based(group: int, logical_id: int, index: int, expected: int) -> None:
    assert index_based(group, logical_id, index) == expected
    assert not index_based(group, logical_id, index) & LOGICAL_BIT


@pytest.mark.parametrize(
    ("axis", "element", "offset"), [(3, 0x17, 0x30017), (1, 0x18, 0x10018), (0x12, 0x2, 0x120002)]
)
def test_axis_offset_and_split(axis: int, element: int, offset: int) -> None:
    assert axis_offset(axis, element) == offset
    assert split_axis_offset(offset) == (axis, element)


def test_split_axis_offset_of_a_channel_object() -> None:
    assert split_axis_offset(0x56) == (0, 0x56)


# --------------------------------------------------------------------------- model


def test_access_flags() -> None:
    assert (Access.READ.readable, Access.READ.writable) == (True, False)
    assert (Access.WRITE.readable, Access.WRITE.writable) == (False, True)
    assert (Access.READ_WRITE.readable, Access.READ_WRITE.writable) == (True, True)
    assert [a.value for a in Access] == ["r", "w", "rw"]


def test_describe_is_the_browse_descriptor(by_name: dict[str, CncObject]) -> None:
    obj = by_name["ch1.mc_command_feed_override_w"]
    assert obj.describe() == [
        "ch1.mc_command_feed_override_w",
        553,
        0x120101,
        0x09,
        "UNS16",
        2,
        "w",
        "0.1 %",
        obj.description,
        [],  # not an enumeration: no value names
        ["%", 0.1, 1],  # people read it in %, value = raw x 0.1, resolution 0.1 %
    ]
    assert obj.description


# --------------------------------------------------------------------------- engineering units


@pytest.mark.parametrize(("name", "scale"), [
    ("ch1.ax1.command_position_acs", ("mm", 1e-4, 4)),  # SGN32 in 0.1 um
    ("ch1.dist_prog_start", ("mm", 1e-4, 4)),  # REAL64 in 0.1 um
    ("ch1.ax1.manual_increment_w", ("mm", 1e-4, 4)),
    ("ch1.actual_path_velocity", ("mm/min", 0.06, 3)),  # um/s
    ("ch1.mc_active_feed_override_r", ("%", 0.1, 1)),  # 0.1 %
    ("ch1.mc_spindle_cmd_rev_r", ("rpm", 1 / 6000, 3)),  # 0.001 deg/s
    ("ch1.ax1.vel_max", ("mm/s", 1.0, 3)),  # read as it is, resolution only
    ("ch1.program_time", ("s", 1.0, 6)),
])
def test_objects_carry_their_engineering_scale(
    by_name: dict[str, CncObject], name: str, scale: tuple[str, float, int]
) -> None:
    obj = by_name[name]
    assert obj.scale == EngineeringScale(*scale)
    assert obj.describe()[10] == list(scale)


def test_objects_without_a_unit_or_with_value_names_have_no_scale(
    by_name: dict[str, CncObject],
) -> None:
    for obj in by_name.values():
        if obj.unit in ("-", "byte", "pulses") or obj.values is not None:
            assert obj.scale is None and obj.describe()[10] == [], obj.name
    # every unit of the catalog is either scaled or deliberately left as it is (ns: the
    # alarms' wall-clock and kernel timestamps, counts since the epoch, not quantities)
    assert {o.unit for o in by_name.values() if o.scale is None} <= {
        "-", "byte", "pulses", "ns"}


# --------------------------------------------------------------------------- value names

# Every enumeration object of the catalog (element name) and its value set.
ENUMERATIONS = {
    "mc_active_mode_r": ChannelMode,
    "mc_command_mode_w": ChannelMode,
    "mc_active_state_r": ChannelState,
    "link_state": LinkState,
    "block_type": ContourBlockType,
    "operation_mode": ManualOperationMode,  # hb_display_r.operation_mode
    "manual_operation_mode_w": ManualOperationMode,
    "mc_wait_reason_r": WaitReason,
    "mode_r": SpindleMode,  # gpCh[i].spindle.mode_r
    "mc_spindle_mode_r": SpindleMode,
    "mc_coolant_state_r": CoolantState,
    "mc_g00_override_mode_r": RapidOverrideMode,
    # alarm slots (by their element with the slot number left out)
    "alarm_active[].class": AlarmClass,
    "alarm_active[].state": AlarmState,
    "alarm_history[].class": AlarmClass,
    "alarm_history[].state": AlarmState,
}


def _enumeration_key(element: str) -> str:
    """The key of ``element`` in ``ENUMERATIONS``: an alarm slot's field without its
    number, else the last step of the element."""
    slot = re.sub(r"\[\d+\]", "[]", element)
    return slot if slot in ENUMERATIONS else element.rsplit(".", 1)[-1]


def test_enumeration_objects_name_their_values(by_name: dict[str, CncObject]) -> None:
    state = by_name["ch2.mc_active_state_r"]
    assert state.value_names == {
        1: "DESELECTED", 2: "SELECTED", 3: "READY", 4: "ACTIVE", 5: "HOLD", 6: "ERROR",
    }
    assert by_name["ch1.ax3.link_state"].value_names == {
        0: "LINKED", 1: "REQUESTED", 2: "WAITING_ACK",
    }
    assert by_name["ch1.mc_command_mode_w"].value_names[2] == "AUTOMATIC"
    assert by_name["gpCh[1].contour_lookahead.response.block[31].block_type"].value_names[6] == (
        "POLYNOMIAL"
    )
    assert state.describe()[9] == [[1, "DESELECTED"], [2, "SELECTED"], [3, "READY"],
                                   [4, "ACTIVE"], [5, "HOLD"], [6, "ERROR"]]


def test_only_enumerations_carry_value_names(by_name: dict[str, CncObject]) -> None:
    """Bit sets (execution mode), booleans, counters and sentinels ("-1 = none") are not
    enumerations: their value names are empty."""
    for obj in by_name.values():
        element = _enumeration_key(obj.element)
        assert obj.values is ENUMERATIONS.get(element), obj.name
        assert bool(obj.value_names) == (element in ENUMERATIONS), obj.name
    assert by_name["ch1.mc_active_execution_mode_r"].value_names == {}
    assert by_name["gpCh[0].decoder_mc_control.execution_mode.state_r"].value_names == {}


def test_cnc_objects_are_frozen(by_name: dict[str, CncObject]) -> None:
    with pytest.raises(AttributeError):
        by_name["ch1.dist_prog_start"].offset = 0x57  # type: ignore[misc]
