"""Mode selection: the mode bar of the current channel, its keys and what they write.

The bar shows the channel modes an operator chooses (``SELECTABLE``, the kernel's
``mc_command_mode_w`` values) with their keys, the active one (``mc_active_mode_r``)
highlighted; a click on a mode or its key (F2..F5) writes ``ch<c>.mc_command_mode_w``.
The kernel chooses a mode only while the channel does not work (DESELECTED, SELECTED,
READY): otherwise it refuses with ADS 0x707 and a sentence, shown on the message line.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from textual.containers import Horizontal
from textual.events import Click
from textual.message import Message
from textual.widgets import Static

from cnc_objects.clients.client import AsyncClient
from cnc_objects.protocol.values import ChannelMode

from .machine import ChannelView


@dataclass(frozen=True, slots=True)
class ModeKey:
    """One selectable mode and the key that selects it."""

    mode: ChannelMode
    key: str  # textual key name


#: The modes of the bar, in the order shown (REFERENCE is not a mode the kernel offers).
SELECTABLE: tuple[ModeKey, ...] = (
    ModeKey(ChannelMode.AUTOMATIC, "f2"),
    ModeKey(ChannelMode.MDI, "f3"),
    ModeKey(ChannelMode.MANUAL, "f4"),
    ModeKey(ChannelMode.STANDBY, "f5"),
)


async def select_mode(client: AsyncClient, channel: ChannelView, mode: ChannelMode) -> str:
    """Command ``mode`` in ``channel``; the line the message bar shows."""
    await client.write(channel.obj("mc_command_mode_w"), int(mode))
    return f"ch{channel.id}: mode {mode.name}"


class ModeButton(Static):
    """One mode of the bar; a click chooses it."""

    def __init__(self, choice: ModeKey) -> None:
        super().__init__(f"{choice.key.upper()} {choice.mode.name}", markup=False,
                         id=f"mode-{choice.mode.name.lower()}", classes="mode")
        self.choice = choice

    def on_click(self, event: Click) -> None:
        """Ask the app to select this mode."""
        event.stop()
        self.post_message(ModeBar.Chosen(self.choice.mode))


class ModeBar(Horizontal):
    """``ch1 mode: [F2 AUTOMATIC] F3 MDI F4 MANUAL F5 STANDBY`` for the current channel,
    and on its right the jog line (axis, increment) that the manual keys use."""

    DEFAULT_CSS = """
    ModeBar { height: 1; padding: 0 1; }
    ModeBar .mode { width: auto; padding: 0 1; color: $text-muted; }
    ModeBar .mode.active { background: $accent; color: $text; text-style: bold; }
    ModeBar #mode-channel { width: auto; padding: 0 1 0 0; }
    ModeBar #jog-line { width: 1fr; text-align: right; color: $text-muted; }
    """

    class Chosen(Message):
        """The operator clicked a mode."""

        def __init__(self, mode: ChannelMode) -> None:
            super().__init__()
            self.mode = mode

    def __init__(self, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.active: dict[str, int] = {}  # per channel key: mc_active_mode_r
        self.current = ""  # key of the channel shown
        self.jog_line = Static("", markup=False, id="jog-line")

    def compose(self) -> Any:
        """The channel, one button per selectable mode, the jog line."""
        yield Static("mode", markup=False, id="mode-channel")
        for choice in SELECTABLE:
            yield ModeButton(choice)
        yield self.jog_line

    def show_channel(self, channel: ChannelView) -> None:
        """Show the mode of ``channel`` (the current one)."""
        self.current = channel.key
        self.query_one("#mode-channel", Static).update(f"{channel.key} mode:")
        self._highlight()

    def mode_changed(self, channel: ChannelView, mode: int) -> None:
        """A channel's ``mc_active_mode_r`` (a feed's value)."""
        self.active[channel.key] = mode
        if channel.key == self.current:
            self._highlight()

    @property
    def shown_mode(self) -> str:
        """The name of the highlighted mode ("" when none is)."""
        return next((b.choice.mode.name for b in self.query(ModeButton)
                     if b.has_class("active")), "")

    def _highlight(self) -> None:
        mode = self.active.get(self.current)
        for button in self.query(ModeButton):
            button.set_class(button.choice.mode == mode, "active")
