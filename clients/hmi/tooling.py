"""The tool and work offset table: per channel the tool in the spindle, the tool
selected, D with its radius and length, and the zero offset in effect
(docs/tools-offsets.md)."""

from __future__ import annotations

from typing import Any

from . import text
from .fixed_table import FixedColumnsTable
from .machine import Machine
from .session import Feed

# column key, header, width
COLUMNS: tuple[tuple[str, str, int], ...] = (
    ("channel", "ch", 3),
    ("tool", "tool", 6),
    ("selected", "T sel", 6),
    ("d", "D", 5),
    ("radius", "radius mm", 11),
    ("length", "length mm", 11),
    ("offset", "offset", 8),
)


def tool_number(value: int) -> str:
    """``T5``; ``-`` for none (0)."""
    return f"T{value}" if value else "-"


def zero_offset(group: int) -> str:
    """G53..G59 for np_grp 0..6, ``G159=i`` beyond."""
    return f"G{53 + group}" if group <= 6 else f"G159={group}"


class ToolingTable(FixedColumnsTable):
    """``mc_active_tool_r``, ``mc_selected_tool_r``, ``mc_active_tool_offset_r``,
    ``mc_active_tool_radius_r``, ``mc_active_tool_length_r`` and
    ``mc_active_zero_offset_r`` of each channel."""

    DEFAULT_CSS = "ToolingTable { height: auto; max-height: 8; }"
    COLUMNS = COLUMNS

    def __init__(self, **kwargs: Any) -> None:
        super().__init__(cursor_type="none", **kwargs)
        self.can_focus = False  # the keys belong to the channel table and the app

    def load(self, machine: Machine) -> None:
        """One row per channel of ``machine``, values to come from the feeds."""
        self.clear()
        for channel in machine.channels:
            self.add_waiting_row(str(channel.id), channel.key)

    def feeds(self, machine: Machine) -> list[Feed]:
        """The subscriptions that fill the table: six per channel."""
        feeds: list[Feed] = []
        for ch in machine.channels:
            cell = self._setter(ch.key)
            feeds += [
                Feed(ch.obj("mc_active_tool_r"), cell("tool", tool_number)),
                Feed(ch.obj("mc_selected_tool_r"), cell("selected", tool_number)),
                Feed(ch.obj("mc_active_tool_offset_r"), cell("d", lambda v: f"D{v}")),
                Feed(ch.obj("mc_active_tool_radius_r"), cell("radius", text.mm)),
                Feed(ch.obj("mc_active_tool_length_r"), cell("length", text.mm)),
                Feed(ch.obj("mc_active_zero_offset_r"), cell("offset", zero_offset)),
            ]
        return feeds


