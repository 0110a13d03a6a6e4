"""The axes table: every axis of every channel, with the drive it outputs to."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from rich.text import Text

from . import text
from .fixed_table import FixedColumnsTable
from .machine import AxisView, Machine
from .session import Feed

# column key, header, width
COLUMNS: tuple[tuple[str, str, int], ...] = (
    ("axis", "axis", 8),
    ("command", "command mm", 12),
    ("actual", "actual mm", 12),
    ("offset", "offset mm", 11),
    ("link", "link", 18),
)
POSITION_CYCLE_MS = 20  # positions are checked for a change every 20 ms (50 Hz) of kernel time


class AxesTable(FixedColumnsTable):
    """Command position (``ch<c>.ax<a>.command_position_acs``), actual position of its drive
    (``ax<A>.actual_position_acs``), position offset (``position_offset``) and link state
    (``link_state`` with ``actual_link_to_physical_axis``) of each channel axis."""

    DEFAULT_CSS = "AxesTable { height: auto; max-height: 16; }"
    COLUMNS = COLUMNS

    def __init__(self, **kwargs: Any) -> None:
        super().__init__(cursor_type="none", **kwargs)
        self.can_focus = False  # the keys belong to the channel table and the app
        self._link: dict[str, list[int]] = {}  # per row: [link_state, actual drive]

    def load(self, machine: Machine) -> None:
        """One row per channel axis of ``machine``, values to come from the feeds."""
        self.clear()
        for channel in machine.channels:
            for axis in channel.axes:
                self.add_waiting_row(f"ch{axis.channel}.{axis.name}", axis.key)
                self._link[axis.key] = [0, 0]

    def feeds(self, machine: Machine) -> list[Feed]:
        """The subscriptions that fill the table: per axis three, per drive one."""
        axes = [a for c in machine.channels for a in c.axes]
        feeds: list[Feed] = []
        for axis in axes:
            feeds += [
                Feed(axis.obj("command_position_acs"),
                     self._cells([axis], "command", text.mm_shown), POSITION_CYCLE_MS,
                     engineering=True),
                Feed(axis.obj("position_offset"), self._cells([axis], "offset", text.mm_shown),
                     POSITION_CYCLE_MS, engineering=True),
                Feed(axis.obj("link_state"), self._link_part(axis, 0)),
                Feed(axis.obj("actual_link_to_physical_axis"), self._link_part(axis, 1)),
            ]
        for drive in machine.drives:  # a drive's actual position fills each axis linked to it
            linked = [a for a in axes if a.drive == drive]
            feeds.append(Feed(f"ax{drive}.actual_position_acs",
                              self._cells(linked, "actual", text.mm_shown), POSITION_CYCLE_MS,
                              engineering=True))
        return feeds


    def _cells(
        self, axes: list[AxisView], column: str, show: Callable[[Any], str]
    ) -> Callable[[Any], None]:
        def apply(value: Any) -> None:
            shown = Text(show(value), justify="right")
            for axis in axes:
                self.update_cell(axis.key, column, shown)
        return apply

    def _link_part(self, axis: AxisView, part: int) -> Callable[[Any], None]:
        def apply(value: int) -> None:
            parts = self._link[axis.key]
            parts[part] = value
            self.update_cell(axis.key, "link", Text(text.link(*parts)))
        return apply
