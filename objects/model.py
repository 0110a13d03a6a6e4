"""The CNC object: a typed value at an ADS address, with a name people read."""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum, IntEnum
from typing import Any

from cnc_objects.protocol.datatypes import DataType
from cnc_objects.protocol.values import value_names

from .units import EngineeringScale, scale_of


class Access(str, Enum):  # noqa: UP042  (str() of a member must stay "Access.X", as before)
    """Who may do what with an object, in the ISG tables' spelling."""

    READ = "r"  # read-only: writes get ADS 0x704
    WRITE = "w"  # write-only, a command: the service reads back the value last written
    READ_WRITE = "rw"  # both

    @property
    def readable(self) -> bool:
        """True when the object shows a state of its own; a write-only command has none
        (the service binds it to the value last written, as a PLC command variable)."""
        return self is not Access.WRITE

    @property
    def writable(self) -> bool:
        """True when the object can be written."""
        return self is not Access.READ


@dataclass(frozen=True, slots=True)
class CncObject:
    """One CNC object instance.

    ``name`` is the instance name (``ch1.ax2.link_state``), ``element`` the name of the
    object in the ISG tables (``link_state``). ``group`` is the logical index group (bit
    0x100000 set); ``channel`` and ``axis`` are the logical channel id and the axis
    number (axis index in the channel, or physical axis number) the instance belongs to,
    0 where they do not apply. ``values`` is the value set of an enumeration object
    (``ChannelState`` for ``mc_active_state_r``), None for every other object.
    """

    name: str
    element: str
    port: int
    group: int
    offset: int
    dtype: DataType
    access: Access
    unit: str
    description: str
    channel: int = 0
    axis: int = 0
    values: type[IntEnum] | None = None

    @property
    def length(self) -> int:
        """Size of the value in bytes."""
        return self.dtype.size

    @property
    def value_names(self) -> dict[int, str]:
        """``{3: "READY", ...}`` for an enumeration object; empty for any other."""
        return value_names(self.values) if self.values is not None else {}

    @property
    def scale(self) -> EngineeringScale | None:
        """How people read the value (0.1 um -> mm); None for an object without a unit
        or an enumeration."""
        return None if self.values is not None else scale_of(self.unit)

    def describe(self) -> list[Any]:
        """The browse descriptor: [name, port, group, offset, type, length, access, unit,
        description, value names, engineering scale]. The value names are ``[[value,
        name], ...]`` (empty for an object that is not an enumeration): pairs, because
        msgpack maps with integer keys are refused by the frame decoder (string keys
        only). The scale is ``[unit, factor, decimals]`` (objects/units.py), empty for an
        object without one."""
        scale = self.scale
        return [
            self.name,
            self.port,
            self.group,
            self.offset,
            self.dtype.name,
            self.length,
            self.access.value,
            self.unit,
            self.description,
            [[value, name] for value, name in self.value_names.items()],
            scale.describe() if scale is not None else [],
        ]
