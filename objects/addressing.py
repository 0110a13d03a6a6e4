"""Address rules of ISG CNC objects (reference/cnc-objects.md, section 2).

* Bit 0x100000 in an index group selects logical addressing (channel by its logical
  id); without it the same group addresses the n-th configured channel (index-based).
* Channel objects carry the channel in the group: ``0x12130<CID>`` (GEO interpolator),
  ``0x12010<CID>`` (COM channel).
* Axis objects carry the axis in the upper 16 bits of the offset: ``0x<AID>00xx``.
"""

from __future__ import annotations

from enum import IntEnum

LOGICAL_BIT = 0x100000


class GroupBase(IntEnum):
    """Logical index-group bases; a channel object adds its channel id."""

    COM_CHANNEL = 0x120100  # COM channel data, + CID (platform data at + 0)
    COM_PLATFORM_AXIS = 0x120200  # COM platform axes, offset 0x<ANo>00xx
    GEO_POSITION_CONTROL = 0x120300  # GEO position controller, platform axes
    GEO_INTERPOLATOR = 0x121300  # GEO interpolator (IPO/BAHN) class, + CID
    GEO_DECODER = 0x122300  # decoder class (SDA variables), + CID
    GEO_HLD = 0x123300  # HLD class, + CID
    GEO_PATH_PREPARATION = 0x124300  # BAVO class, + CID
    COM_DIRECTORY = 0x130100  # COM object directory, + channel (0 = platform)
    COM_TOOL_LIST = 0x120600  # project: the tool list's name, wear and life, + CID


def channel_group(base: int, channel_id: int) -> int:
    """The logical group of a channel object: ``base + CID``."""
    return base + channel_id


def index_based(group: int, logical_id: int, index: int) -> int:
    """The index-based spelling of a logical channel group.

    ``index`` is the channel's position in the configuration (from 1); the logical id is
    replaced by it and bit 0x100000 is cleared.
    """
    return (group - logical_id + index) & ~LOGICAL_BIT


def axis_offset(axis: int, element: int) -> int:
    """Offset of an axis object: axis number in the upper 16 bits."""
    return (axis << 16) | element


def split_axis_offset(offset: int) -> tuple[int, int]:
    """(axis, element) of an axis-object offset."""
    return offset >> 16, offset & 0xFFFF
