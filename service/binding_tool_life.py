"""Binds the tool list's name, wear and life (``objects.catalog_tools.TOOL_EXTRA_FIELDS``).

Name, wear and life_max are fields of the row (``SetToolData``); life_used is the
channel's cutting count (``kernel.tool_life``) in seconds; life_expired compares both.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from cnc_objects.objects import CncObject

from .binding_types import Binder, Getter, WriteBinder
from .kernel.commands import Command
from .kernel.commands_tooling import SetToolData, SetToolLifeUsed
from .kernel.kernel import Kernel
from .kernel.nc.tool_data import ToolData, ToolField
from .kernel.state import Channel

_ROW_FIELD = {"name": ToolField.NAME, "wear": ToolField.WEAR, "life_max": ToolField.LIFE_MAX}


def _used_s(ch: Channel, i: int, cycle_s: float) -> float:
    return ch.tool_cut_cycles.get(i, 0) * cycle_s


_VALUE: dict[str, Callable[[ToolData, float], Any]] = {
    "name": lambda row, used: row.name,
    "wear": lambda row, used: row.wear_01um,
    "life_max": lambda row, used: row.life_max_s,
    "life_used": lambda row, used: used,
    "life_expired": lambda row, used: row.life_max_s > 0.0 and used >= row.life_max_s,
}


def tool_extra_reader(i: int, name: str) -> Binder:
    """The reader of field ``name`` of row ``i``."""
    value = _VALUE[name]

    def bind(kernel: Kernel, obj: CncObject) -> Getter:
        ci, cycle_s = kernel.channel_index(obj.channel), kernel.cycle_s

        def get() -> Any:
            ch = kernel.snapshot.channels[ci]
            return value(ch.tooling.tools.row(i), _used_s(ch, i, cycle_s))

        return get

    return bind


def tool_extra_writer(i: int, name: str) -> WriteBinder | None:
    """The writer of field ``name`` of row ``i`` (None: read only)."""
    if name == "life_used":
        def used(kernel: Kernel, obj: CncObject) -> Callable[[Any], Command]:
            ci, cycle_s = kernel.channel_index(obj.channel), kernel.cycle_s
            return lambda value: SetToolLifeUsed(ci, i, float(value), cycle_s)

        return used
    which = _ROW_FIELD.get(name)
    if which is None:
        return None

    def bind(kernel: Kernel, obj: CncObject) -> Callable[[Any], Command]:
        ci = kernel.channel_index(obj.channel)
        return lambda value: SetToolData(ci, i, which, value)

    return bind
