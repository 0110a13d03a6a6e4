"""Object templates and how they are expanded over a machine.

An ``ObjectTemplate`` is one row of the ISG object tables (reference/cnc-objects.md)
before channel and axis are filled in; ``instances`` expands templates over a
``MachineLayout``. The catalog's areas (``catalog`` lists them) each give their
templates for the sizes a machine configures (``CatalogSizes``).
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum, IntEnum
from typing import NamedTuple

from cnc_objects.protocol.constants import CncPort
from cnc_objects.protocol.datatypes import DataType

from .addressing import axis_offset, channel_group
from .model import Access, CncObject


class Scope(Enum):
    """What one template is instantiated for."""

    PLATFORM = "platform"  # once: name = element
    PHYSICAL_AXIS = "physical_axis"  # per drive: ax<A>.element, offset 0x<A>00xx
    CHANNEL = "channel"  # per channel: ch<c>.element, group + CID
    CHANNEL_AXIS = "channel_axis"  # per axis of a channel: ch<c>.ax<a>.element
    PLC_CHANNEL = "plc_channel"  # HLI per channel: gpCh[i].element, i = channel index from 0
    PLC_MC = "plc_mc"  # older HLI per channel: pMC[i].element (same address block as gpCh[i])
    PLC_AXIS = "plc_axis"  # HLI per axis: gpAx[i].element, i = HLI axis slot from 0
    PLC_CHANNEL_AXIS = "plc_channel_axis"  # HLI per axis of a channel:
    # gpCh[i].bahn_state.coord_r[k].element, k = axis index in the channel from 0


@dataclass(frozen=True, slots=True)
class ObjectTemplate:
    """One object of the tables, before channel and axis are filled in. ``values``:
    the value set of an enumeration object (its value names go out with browse)."""

    element: str
    scope: Scope
    port: CncPort
    group_base: int
    offset: int
    dtype: DataType
    access: Access
    unit: str
    description: str
    values: type[IntEnum] | None = None


@dataclass(frozen=True, slots=True)
class ChannelLayout:
    """A channel: its logical id and the number of axes it has."""

    channel_id: int
    axis_count: int


@dataclass(frozen=True, slots=True)
class MachineLayout:
    """What the catalog is expanded over: channels, physical axis numbers, and the axis
    numbers of the HLI axis slots ``gpAx[0..]`` in slot order."""

    channels: tuple[ChannelLayout, ...]
    physical_axes: tuple[int, ...]
    hli_axes: tuple[int, ...] = ()


class CatalogSizes(NamedTuple):
    """The table sizes a machine configures: rows of the tool list, zero offset groups
    (group 0 is G53: groups 1..n-1 have objects) and alarm history slots."""

    tool_entries: int = 0
    zero_offset_groups: int = 1
    alarm_history: int = 0


# PLC symbols (port 851) live in the PLC's memory area like TwinCAT PLC variables; the
# offsets are this project's layout (clients find symbols by name or handle).
PLC_GROUP = 0x4020
PLC_CHANNEL_BASE, PLC_CHANNEL_STRIDE = 0x10000, 0x1000
PLC_AXIS_BASE, PLC_AXIS_STRIDE = 0x80000, 0x100
# gpCh[i].bahn_state.coord_r[k] (per axis of the channel, k from 0), after the technology
# units and the spindle (0xD00..0xE30) and bahn_state.dist_prog_start (0xE38), so that
# bahn_state is one block, as a compiler lays it out: room for 28 axes before the next
# channel's area
PLC_COORD_BASE, PLC_COORD_STRIDE = 0xE40, 0x10

def instantiate(
    t: ObjectTemplate, channel: int = 0, axis: int = 0, index: int = 0
) -> CncObject:
    match t.scope:
        case Scope.PLC_CHANNEL | Scope.PLC_MC:
            prefix = "gpCh" if t.scope == Scope.PLC_CHANNEL else "pMC"
            name, group = f"{prefix}[{index}].{t.element}", t.group_base
            offset = PLC_CHANNEL_BASE + index * PLC_CHANNEL_STRIDE + t.offset
        case Scope.PLC_AXIS:
            name, group = f"gpAx[{index}].{t.element}", t.group_base
            offset = PLC_AXIS_BASE + index * PLC_AXIS_STRIDE + t.offset
        case Scope.PLC_CHANNEL_AXIS:
            name, group = f"gpCh[{index}].bahn_state.coord_r[{axis - 1}].{t.element}", t.group_base
            offset = (PLC_CHANNEL_BASE + index * PLC_CHANNEL_STRIDE + PLC_COORD_BASE
                      + (axis - 1) * PLC_COORD_STRIDE + t.offset)
        case Scope.PLATFORM:
            name, group, offset = t.element, t.group_base, t.offset
        case Scope.PHYSICAL_AXIS:
            name, group, offset = f"ax{axis}.{t.element}", t.group_base, axis_offset(axis, t.offset)
        case Scope.CHANNEL:
            name, group, offset = (
                f"ch{channel}.{t.element}",
                channel_group(t.group_base, channel),
                t.offset,
            )
        case Scope.CHANNEL_AXIS:
            name, group, offset = (
                f"ch{channel}.ax{axis}.{t.element}",
                channel_group(t.group_base, channel),
                axis_offset(axis, t.offset),
            )
    return CncObject(
        name, t.element, t.port, group, offset, t.dtype, t.access, t.unit, t.description,
        channel, axis, t.values,
    )


def instances(layout: MachineLayout, templates: tuple[ObjectTemplate, ...]) -> list[CncObject]:
    """Every object instance of ``layout``: platform, physical axes, channels, their axes."""
    objects: list[CncObject] = []
    for t in templates:
        match t.scope:
            case Scope.PLATFORM:
                objects.append(instantiate(t))
            case Scope.PHYSICAL_AXIS:
                objects.extend(instantiate(t, axis=a) for a in layout.physical_axes)
            case Scope.CHANNEL:
                objects.extend(instantiate(t, c.channel_id) for c in layout.channels)
            case Scope.CHANNEL_AXIS:
                objects.extend(
                    instantiate(t, c.channel_id, a)
                    for c in layout.channels
                    for a in range(1, c.axis_count + 1)
                )
            case Scope.PLC_CHANNEL | Scope.PLC_MC:
                objects.extend(
                    instantiate(t, c.channel_id, index=i) for i, c in enumerate(layout.channels)
                )
            case Scope.PLC_CHANNEL_AXIS:
                objects.extend(
                    instantiate(t, c.channel_id, a, index=i)
                    for i, c in enumerate(layout.channels)
                    for a in range(1, c.axis_count + 1)
                )
            case Scope.PLC_AXIS:
                objects.extend(
                    instantiate(t, axis=n, index=i) for i, n in enumerate(layout.hli_axes)
                )
    return objects
