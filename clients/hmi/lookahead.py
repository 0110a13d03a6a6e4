"""The contour look-ahead panel: elements of the compensated path ahead (FCT-C40).

The elements are not a subscription: each view is a *request* through the PLC control
unit ``gpCh[i].contour_lookahead`` (``AsyncClient.contour_lookahead``), repeated by the
app every ``REFRESH_S`` and whenever the channel finishes a block.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import IntEnum
from typing import Any

from rich.text import Text
from textual.containers import Vertical
from textual.widgets import DataTable, Static

from cnc_objects.clients.channel_ops import ContourReply
from cnc_objects.clients.client import AsyncClient

from . import text
from .machine import ChannelView

REFRESH_S = 0.5  # wall time between two requests while the panel is shown
MIN_GAP_S = 0.05  # at least this between two requests: short blocks end faster than that
WINDOW_01UM = 1e9  # mode 2 window length: 100 m, i.e. everything prepared ahead


class LookaheadMode(IntEnum):
    """Which elements a request asks for."""

    MARKED_AREA = 1  # mode 1: the log of the #CONTOUR LOOKAHEAD LOG ON area, from index 0
    AHEAD = 2  # mode 2: elements starting at or after the current path distance


@dataclass(frozen=True, slots=True)
class LookaheadView:
    """One answer, with what was asked."""

    channel: ChannelView
    mode: LookaheadMode
    from_01um: float  # mode 2: the path distance the window starts at
    reply: ContourReply


async def fetch(client: AsyncClient, channel: ChannelView, mode: LookaheadMode) -> LookaheadView:
    """Ask the CNC for the elements of ``channel`` in ``mode`` (two or three round trips)."""
    start = 0.0
    if mode is LookaheadMode.AHEAD:
        start = await client.read(channel.obj("dist_prog_start"))
    reply = await client.contour_lookahead(
        start, WINDOW_01UM if mode is LookaheadMode.AHEAD else 0.0,
        plc_channel=channel.plc_index,
    )
    return LookaheadView(channel, mode, start, reply)


# column key, header, width
COLUMNS: tuple[tuple[str, str, int], ...] = (
    ("type", "type", 10),
    ("n", "N", 6),
    ("count", "block", 6),
    ("start", "start mm", 11),
    ("length", "length mm", 10),
    ("r_prog", "R prog mm", 10),
    ("r_comp", "R comp mm", 10),
    ("angle", "angle °", 8),
    ("tangent", "tangent °", 9),
)


def _deg(rad: float) -> str:
    return f"{math.degrees(rad):.1f}"


class LookaheadPanel(Vertical):
    """A title line (mode, prepared distance, logged entries) and one row per element."""

    DEFAULT_CSS = """
    LookaheadPanel { height: auto; max-height: 20; border: round $accent; display: none; }
    LookaheadPanel > Static { height: auto; }
    LookaheadPanel > DataTable { height: auto; max-height: 17; }
    """

    def __init__(self, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.view: LookaheadView | None = None  # the last answer shown
        self.summary = Static("", markup=False)
        self.table: DataTable[str | Text] = DataTable(cursor_type="none")
        self.table.can_focus = False

    def compose(self) -> Any:
        """Summary line above the element table."""
        yield self.summary
        yield self.table

    def on_mount(self) -> None:
        """Columns are fixed: widths do not jump between requests."""
        self.border_title = "contour look-ahead"
        for key, label, width in COLUMNS:
            self.table.add_column(label, key=key, width=width)

    def show(self, view: LookaheadView) -> None:
        """Show one answer."""
        self.view = view
        reply = view.reply
        asked = ("marked area (mode 1, from index 0)" if view.mode is LookaheadMode.MARKED_AREA
                 else f"ahead of {text.mm(view.from_01um)} mm (mode 2)")
        self.border_title = f"ch{view.channel.id} contour look-ahead: {asked}"
        self.summary.update(
            f"prepared up to {text.mm(reply.max_dist_prog_start)} mm, "
            f"{reply.count_logged_blocks} logged, log {'active' if reply.log_active else 'closed'}"
            f", {len(reply.blocks)} elements — a request, repeated every {REFRESH_S:g} s "
            "and at each block end"
        )
        self.table.clear()
        for b in reply.blocks:
            self.table.add_row(
                text.block_type(b.block_type),
                Text(str(b.block_number) if b.block_number >= 0 else "-", justify="right"),
                Text(str(b.block_count_r), justify="right"),
                Text(text.mm(b.start_position), justify="right"),
                # LOG entries carry the PARAM value as programmed in `length`
                Text(text.mm(b.length) if b.block_type in (1, 2, 6) else f"{b.length:g}", justify="right"),
                Text(text.mm(b.programmed_radius), justify="right"),
                Text(text.mm(b.compensated_radius), justify="right"),
                Text(_deg(b.circle_angle), justify="right"),
                Text(_deg(b.tangent_variation), justify="right"),
            )

    def show_error(self, channel: ChannelView, message: str) -> None:
        """Show why no answer came (e.g. ADS 0x701: the channel has no FCT_CONTOUR_LAH)."""
        self.view = None
        self.border_title = f"ch{channel.id} contour look-ahead"
        self.summary.update(message)
        self.table.clear()
