"""The channel table (one row per channel) and the error list of the current channel."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from rich.text import Text
from textual.widgets import Static

from cnc_objects.clients.channel_ops import describe_wait_reason
from cnc_objects.clients.client import AsyncClient

from . import text
from .fixed_table import FixedColumnsTable
from .machine import ChannelView, Machine
from .session import Feed

# column key, header, width
COLUMNS: tuple[tuple[str, str, int], ...] = (
    ("channel", "ch", 3),
    ("mode", "mode", 9),
    ("state", "state", 10),
    ("program", "program", 16),
    ("block", "block", 20),
    ("override", "override", 8),
    ("feed", "mm/min", 7),
    ("single", "single", 6),
    ("waits", "waits for", 16),  # the wait reason (mc_wait_reason_r), "-" when none
    ("output", "output", 9),
    ("errors", "errors", 6),
    ("spindle", "spindle", 4),
    ("rpm", "rpm", 7),
)
SPINDLE_MODES = {1: "M5", 2: "M3", 4: "M4", 8: "M19"}  # mc_spindle_mode_r
MDEG_S_PER_RPM = 6000.0  # mc_spindle_active_rev_r is in 0.001 degrees/s
SPEED_CYCLE_MS = 100  # the path speed is checked for a change every 100 ms of kernel time


def wait_reason(value: int) -> str:
    """The wait reason's name in lower case ("feed hold"), "-" when the channel does not
    wait."""
    name, _ = describe_wait_reason(value)
    return "-" if value == 0 else name.lower().replace("_", " ")


class ChannelTable(FixedColumnsTable):
    """Mode, state, program, block, override, single block, wait reason, axis output,
    error count and spindle (mode, actual rpm) of every channel. The cursor row is the current channel,
    the one the keys act on."""

    DEFAULT_CSS = "ChannelTable { height: auto; max-height: 12; }"
    COLUMNS = COLUMNS

    def __init__(self, **kwargs: Any) -> None:
        super().__init__(cursor_type="row", zebra_stripes=False, **kwargs)
        self._block: dict[str, dict[str, Any]] = {}  # parts of the block cell per channel

    def load(self, machine: Machine) -> None:
        """One row per channel of ``machine``, values to come from the feeds."""
        self.clear()
        for channel in machine.channels:
            self.add_waiting_row(str(channel.id), channel.key)
            self._block[channel.key] = {"number": -1, "file": "", "line": 0}

    def feeds(self, machine: Machine) -> list[Feed]:
        """The subscriptions that fill the table."""
        feeds: list[Feed] = []
        for ch in machine.channels:
            cell = self._setter(ch.key)
            feeds += [
                Feed(ch.obj("mc_active_mode_r"), cell("mode", text.mode)),
                Feed(ch.obj("mc_active_state_r"), cell("state", text.state)),
                Feed(ch.obj("mc_active_program_name_r"), cell("program", lambda v: v or "-")),
                Feed(ch.obj("actual_block_number"), self._block_part(ch.key, "number")),
                Feed(ch.obj("mc_active_file_name_r"), self._block_part(ch.key, "file")),
                Feed(ch.obj("mc_active_line_r"), self._block_part(ch.key, "line")),
                Feed(ch.obj("mc_active_feed_override_r"), cell("override", text.percent_shown),
                     engineering=True),
                Feed(ch.obj("actual_path_velocity"), cell("feed", text.mm_min_shown),
                     SPEED_CYCLE_MS, engineering=True),
                Feed(ch.obj("mc_active_single_block_r"), cell("single", text.on_off)),
                Feed(ch.obj("mc_wait_reason_r"), cell("waits", wait_reason)),
                Feed(ch.suspend("state_r"),
                     cell("output", lambda v: "suspended" if v else "active")),
                Feed(ch.obj("mc_error_count_r"), cell("errors", str)),
                Feed(ch.obj("mc_spindle_mode_r"),
                     cell("spindle", lambda v: SPINDLE_MODES.get(v, "?"))),
                Feed(ch.obj("mc_spindle_active_rev_r"),
                     cell("rpm", lambda v: f"{v / MDEG_S_PER_RPM:.0f}")),
            ]
        return feeds



    def _block_part(self, row: str, part: str) -> Callable[[Any], None]:
        def apply(value: Any) -> None:
            parts = self._block[row]
            parts[part] = value
            number = f"N{parts['number']}" if parts["number"] >= 0 else "-"
            where = f" {parts['file']}:{parts['line']}" if parts["line"] else ""
            self.update_cell(row, "block", Text(number + where))
        return apply


class ErrorsPanel(Static):
    """The error list (``mc_error_<k>_*``, via ``channel_errors``) of the current channel,
    re-read whenever a channel's ``mc_error_count_r`` changes."""

    DEFAULT_CSS = "ErrorsPanel { height: auto; max-height: 10; border: round $error 50%; }"

    def __init__(self, **kwargs: Any) -> None:
        super().__init__("", markup=False, **kwargs)  # error texts may hold brackets
        self.errors: dict[str, list[str]] = {}  # per channel key: the lines shown
        self._current = ""

    def feeds(self, client: AsyncClient, machine: Machine) -> list[Feed]:
        """One error-count subscription per channel; each change re-reads the list."""
        self.errors = {ch.key: [] for ch in machine.channels}

        def follow(channel: ChannelView) -> Callable[[int], Any]:
            async def apply(count: int) -> None:
                lines = await client.channel_errors(channel.id) if count else []
                self.errors[channel.key] = lines
                if channel.key == self._current:
                    self._render_current()
            return apply

        return [Feed(ch.obj("mc_error_count_r"), follow(ch)) for ch in machine.channels]

    def show_channel(self, channel: ChannelView) -> None:
        """Show the errors of ``channel``."""
        self._current = channel.key
        self._render_current()

    def _render_current(self) -> None:
        lines = self.errors.get(self._current, [])
        self.border_title = f"{self._current} errors"
        self.update("\n".join(lines) if lines else "no errors")
