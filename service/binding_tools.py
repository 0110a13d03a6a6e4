"""Binds the tool and work offset objects (``objects.catalog_tools``) to the kernel.

Reads come from each channel's ``tooling`` view in the snapshot; writes of the tool
list and the zero offset table become ``SetToolData`` / ``SetZeroOffset`` commands,
which refuse values out of range with a sentence (ADS 0x706 on the wire).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from cnc_objects.objects import CncObject
from cnc_objects.objects.catalog_tools import (
    TOOL_EXTRA_FIELDS,
    TOOL_ROW_FIELDS,
    tool_row_element,
    zero_offset_element,
)
from cnc_objects.objects.templates import CatalogSizes

from ..protocol.units import UM01_PER_MM
from .binding_tool_life import tool_extra_reader, tool_extra_writer
from .binding_types import AreaBinding, Binder, Getter, WriteBinder
from .kernel.commands import Command
from .kernel.commands_tooling import SetToolData, SetZeroOffset
from .kernel.kernel import Kernel
from .kernel.nc.tool_data import ToolField
from .kernel.tooling_view import ChannelTooling

_FIELD_OF = {"valid": ToolField.VALID, "radius": ToolField.RADIUS, "laenge": ToolField.LENGTH}


def _tooling(value: Callable[[ChannelTooling], Any]) -> Binder:
    """A value of the channel's tooling view."""
    def bind(kernel: Kernel, obj: CncObject) -> Getter:
        ci = kernel.channel_index(obj.channel)
        return lambda: value(kernel.snapshot.channels[ci].tooling)

    return bind


def _position_pcs(kernel: Kernel, obj: CncObject) -> Getter:
    """ACS command position minus the program shift (zero offset + tool length)."""
    ci, ai = kernel.channel_index(obj.channel), obj.axis - 1

    def get() -> int:
        channel = kernel.snapshot.channels[ci]
        shift = channel.tooling.shift_mm
        shift_01um = round(shift[ai] * UM01_PER_MM) if ai < len(shift) else 0
        return channel.axes[ai].command_position_01um - shift_01um

    return get


def _tool_field(i: int, name: str) -> Binder:
    def value(t: ChannelTooling) -> Any:
        row = t.tools.row(i)
        match _FIELD_OF[name]:
            case ToolField.VALID:
                return row.valid
            case ToolField.RADIUS:
                return row.radius_01um
            case ToolField.LENGTH:
                return row.length_01um

    return _tooling(value)


def _zero_offset(group: int) -> Binder:
    def bind(kernel: Kernel, obj: CncObject) -> Getter:
        ci, ai = kernel.channel_index(obj.channel), obj.axis - 1
        return lambda: (kernel.snapshot.channels[ci].tooling.zero_offsets
                        .offset_01um(group, ai))

    return bind


FIXED_READERS: dict[str, Binder] = {
    "mc_selected_tool_r": _tooling(lambda t: t.tool_selected),
    "mc_active_tool_r": _tooling(lambda t: t.tool_active),
    "mc_active_tool_offset_r": _tooling(lambda t: t.d_active),
    "mc_active_tool_radius_r": _tooling(lambda t: t.radius_01um),
    "mc_active_tool_length_r": _tooling(lambda t: t.length_01um),
    "mc_active_zero_offset_r": _tooling(lambda t: t.zero_offset_group),
    "mc_tool_list_size_r": _tooling(lambda t: t.tools.size),
    "mc_zero_offset_groups_r": _tooling(lambda t: t.zero_offsets.groups),
    "active_zero_offset_group": _tooling(lambda t: t.zero_offset_group),
    "actual_tool_radius": _tooling(lambda t: t.radius_01um),
    "command_position_pcs": _position_pcs,
    "actual_position_pcs": _position_pcs,
}


def tool_readers(sizes: CatalogSizes) -> dict[str, Binder]:
    """Readers of every tool and work offset object of a machine."""
    readers = dict(FIXED_READERS)
    for i in range(1, sizes.tool_entries + 1):
        for name, *_ in TOOL_ROW_FIELDS:
            readers[tool_row_element(i, name)] = _tool_field(i, name)
        for name, *_ in TOOL_EXTRA_FIELDS:  # name, wear, life (binding_tool_life)
            readers[tool_row_element(i, name)] = tool_extra_reader(i, name)
    for g in range(1, sizes.zero_offset_groups):
        readers[zero_offset_element(g)] = _zero_offset(g)
    return readers


def _tool_write(i: int, name: str) -> WriteBinder:
    def bind(kernel: Kernel, obj: CncObject) -> Callable[[Any], Command]:
        ci = kernel.channel_index(obj.channel)
        return lambda value: SetToolData(ci, i, _FIELD_OF[name], value)

    return bind


def _zero_offset_write(group: int) -> WriteBinder:
    def bind(kernel: Kernel, obj: CncObject) -> Callable[[Any], Command]:
        ci, ai = kernel.channel_index(obj.channel), obj.axis - 1
        return lambda value: SetZeroOffset(ci, group, ai, value)

    return bind


def tool_writers(sizes: CatalogSizes) -> dict[str, WriteBinder]:
    """Writers of the tool list and the zero offset table."""
    writers: dict[str, WriteBinder] = {}
    for i in range(1, sizes.tool_entries + 1):
        for name, *_ in TOOL_ROW_FIELDS:
            writers[tool_row_element(i, name)] = _tool_write(i, name)
        for name, *_ in TOOL_EXTRA_FIELDS:
            extra = tool_extra_writer(i, name)
            if extra is not None:
                writers[tool_row_element(i, name)] = extra
    for g in range(1, sizes.zero_offset_groups):
        writers[zero_offset_element(g)] = _zero_offset_write(g)
    return writers


#: tools and work offsets, as many as the machine configures (``objects.catalog_tools``)
BINDING = AreaBinding(tool_readers, tool_writers)
