"""``cnc-hmi [--endpoint URL] [--timeout S] [--key FILE [--server-key FILE]]``: the
terminal HMI of a cnc-objects service.

    .venv/bin/cnc-hmi --endpoint tcp://127.0.0.1:5555

Bad usage (an option that does not parse, a key file it cannot use) exits with code 2
and says which option. A service started with ``--keys`` needs the HMI's key (``--key``
or ``CNC_KEY``; docs/security.md); a refused key is shown on the message line.

The app owns no machine state: tables are filled by subscriptions (``session``), keys
write objects (``control``), the look-ahead panel re-requests (``lookahead``). Key
bindings are in ``HmiApp.BINDINGS`` and in docs/hmi.md.
"""

from __future__ import annotations

import asyncio
import contextlib
import sys
from collections.abc import Awaitable, Callable, Sequence
from pathlib import Path
from typing import Any

import typer
from textual.app import App, ComposeResult
from textual.binding import Binding
from textual.containers import VerticalScroll
from textual.widgets import DataTable, Footer, Header, Input, Label

from cnc_objects.clients.client import DEFAULT_ENDPOINT, AsyncClient, DeviceInfo
from cnc_objects.clients.curve import client_curve
from cnc_objects.clients.errors import AdsError, ClientValueError
from cnc_objects.clients.key_options import key_option, server_key_option
from cnc_objects.protocol.values import ChannelMode

from . import control, manual_keys, text
from .alarms import AlarmLine, AlarmPage
from .axes import AxesTable
from .channels import ChannelTable, ErrorsPanel
from .connection_state import ConnectionLine
from .lookahead import MIN_GAP_S, REFRESH_S, LookaheadMode, LookaheadPanel, fetch
from .machine import ChannelView, Machine
from .mdi import MdiHistory, MdiInput, blocks, default_history_file
from .message_line import MessageLine
from .mode_select import SELECTABLE, ModeBar, select_mode
from .program_picker import ProgramPicker
from .program_view import ProgramView
from .session import Feed, run_sessions
from .tooling import ToolingTable

DEFAULT_TIMEOUT_S = 2.0  # an HMI should say "not reachable" quickly, not after 5 s
Operation = Callable[[AsyncClient, ChannelView], Awaitable[str]]


class HmiApp(App[None]):
    """Channels, axes, program control, jog of path and contour look-ahead of one service."""

    TITLE = "cnc-hmi"
    # Inline, not a .tcss file: package data would need its own line in pyproject.
    CSS = """
    #body { height: 1fr; }
    .title { height: 1; padding: 0 1; color: $text-muted; }
    .stale { opacity: 60%; text-style: dim; }
    """
    ENABLE_COMMAND_PALETTE = False  # every command is a key; the footer needs the room
    BINDINGS = [
        Binding("c", "next_channel", "Channel"),
        Binding("p", "select_program", "Program"),
        Binding("s", "start", "Start"),
        Binding("h", "hold", "Hold"),
        Binding("r", "reset", "Reset"),
        Binding("b", "single_block", "Single"),
        Binding("plus,equals_sign", "override(100)", "Ovr+", key_display="+"),
        Binding("minus", "override(-100)", "Ovr-", key_display="-"),
        Binding("j", "suspend", "Jog path"),
        Binding("l", "lookahead", "Look-ahead"),
        Binding("m", "lookahead_mode", "LA mode"),
        Binding("right_square_bracket", "jog(1)", "Jog+", key_display="]"),
        Binding("left_square_bracket", "jog(-1)", "Jog-", key_display="["),
        Binding("a", "jog_axis", "Jog axis"),
        Binding("i", "jog_increment", "Incr"),
        Binding("space", "jog_release", "Jog stop", show=False),
        Binding("e", "mdi", "MDI"),
        Binding("A", "alarms", "Alarms"),
        *(Binding(m.key, f"select_mode('{m.mode.name}')", m.mode.name, show=False)
          for m in SELECTABLE),
        Binding("q", "quit", "Quit"),
    ]
    _DIALOG_ACTIONS = {"quit"}  # what the keys may still do while the program dialog is open

    def __init__(self, endpoint: str = DEFAULT_ENDPOINT, timeout_s: float = DEFAULT_TIMEOUT_S,
                 key_file: str | None = None, server_key: str | None = None,
                 mdi_history: Path | None = None):
        """``mdi_history``: the file the MDI history is kept in (None: this session only)."""
        super().__init__()
        self.endpoint = endpoint
        self.timeout_s = timeout_s
        self.key_file = key_file  # CURVE keys, for a service with --keys
        self.server_key = server_key
        self.client: AsyncClient | None = None  # None while the service does not answer
        self.machine: Machine | None = None
        self.lookahead_mode = LookaheadMode.AHEAD
        self._lookahead_wake = asyncio.Event()
        self.channels = ChannelTable(id="channels")
        self.axes = AxesTable(id="axes")
        self.tooling = ToolingTable(id="tooling")
        self.errors = ErrorsPanel(id="errors")
        self.lookahead = LookaheadPanel(id="lookahead")
        self.message = MessageLine(id="message")
        self.alarm_line = AlarmLine(id="alarm-line")  # the newest active alarm (alarms.py)
        self.jog_choice = manual_keys.JogChoice()  # manual mode: jog axis and increment
        self.continuous_jog = manual_keys.ContinuousJog()
        self.connection = ConnectionLine(endpoint, id="connection")
        self.mode_bar = ModeBar(id="mode-bar")
        self.program_view = ProgramView(id="program")
        self.mdi = MdiInput(MdiHistory(mdi_history), id="mdi")

    def compose(self) -> ComposeResult:
        """Header, the panels, the message line, the key bindings."""
        yield Header()
        yield self.connection
        yield self.mode_bar
        with VerticalScroll(id="body"):
            yield Label("channels (cursor row = current channel)", classes="title")
            yield self.channels
            yield Label("axes", classes="title")
            yield self.axes
            yield Label("tools and work offsets", classes="title")
            yield self.tooling
            yield self.program_view
            yield self.errors
            yield self.lookahead
        yield self.mdi
        yield self.alarm_line
        yield self.message
        yield Footer(compact=True)

    def on_mount(self) -> None:
        """Start the session with the service (it retries until the service answers)."""
        self.sub_title = f"connecting to {self.endpoint}"
        self.message.say(f"connecting to {self.endpoint} …")
        self.channels.focus()
        self.run_worker(run_sessions(self.endpoint, self.timeout_s, self, self.key_file,
                                     self.server_key),
                        name="session", group="session", exclusive=True)

    # ------------------------------------------------------------ session events

    def session_started(
        self, client: AsyncClient, machine: Machine, info: DeviceInfo
    ) -> Sequence[Feed]:
        """Show the discovered machine; the returned feeds fill it."""
        self.client, self.machine = client, machine
        row = self.channels.cursor_row  # a reconnect keeps the current channel
        self.channels.load(machine)
        self.channels.move_cursor(row=max(0, min(row, len(machine.channels) - 1)))
        self.axes.load(machine)
        self.tooling.load(machine)
        for widget in self._value_widgets():
            widget.remove_class("stale")
        self.connection.session_started(f"{info.name} {info.version}")
        self.sub_title = f"{info.name} {info.version} at {self.endpoint}"
        self.message.say(f"connected to {self.endpoint}: {len(machine.channels)} channels")
        current = self.current_channel
        program_feeds = self.program_view.feeds(client, machine)
        if current is not None:
            self._show_current(current)
        self._lookahead_wake.set()
        block_ends = [Feed(ch.obj("mc_block_count_r"), self._block_finished(ch))
                      for ch in machine.channels]
        modes = [Feed(ch.obj("mc_active_mode_r"), self._mode_changed(ch))
                 for ch in machine.channels]
        return [*self.channels.feeds(machine), *self.axes.feeds(machine),
                *self.tooling.feeds(machine), *self.errors.feeds(client, machine), *block_ends,
                *modes, *program_feeds, *self.alarm_line.feeds(client)]

    def session_lost(self, reason: str) -> None:
        """Say that the service does not answer; the shown values are stale."""
        self.client = None
        self.continuous_jog.forget()
        self.sub_title = f"not connected: {self.endpoint}"
        for widget in self._value_widgets():
            widget.add_class("stale")
        self.connection.session_lost()
        self.message.say(reason, error=True)

    def service_replied(self) -> None:
        """A reply: the connection line's "no reply since" counts from now."""
        self.connection.replied()

    def _value_widgets(self) -> tuple[Any, ...]:
        """The widgets that show values of the service: greyed while it does not reply."""
        return (self.channels, self.axes, self.tooling, self.errors, self.program_view,
                self.mode_bar, self.alarm_line)

    def _mode_changed(self, channel: ChannelView) -> Callable[[int], None]:
        return lambda mode: self.mode_bar.mode_changed(channel, mode)

    def feed_failed(self, feed: Feed, exc: AdsError) -> None:
        """One object could not be subscribed: say which and why."""
        self.message.say(f"cannot follow {feed.name}: {exc}", error=True)

    def _block_finished(self, channel: ChannelView) -> Callable[[Any], None]:
        def apply(_: Any) -> None:
            if self.current_channel == channel:
                self._lookahead_wake.set()  # a new block: ask for the contour again
        return apply

    # ------------------------------------------------------------ current channel

    @property
    def current_channel(self) -> ChannelView | None:
        """The channel of the channel table's cursor row (the one the keys act on)."""
        if self.machine is None or not self.machine.channels:
            return None
        return self.machine.channel(self.channels.cursor_row)

    def on_data_table_row_highlighted(self, event: DataTable.RowHighlighted) -> None:
        """Another current channel: its errors and look-ahead."""
        if event.data_table is self.channels and self.current_channel is not None:
            self._show_current(self.current_channel)
            self._lookahead_wake.set()

    def _show_current(self, channel: ChannelView) -> None:
        """The panels that show the current channel only."""
        self.errors.show_channel(channel)
        self.mode_bar.show_channel(channel)
        self.program_view.show_channel(channel)
        self.mode_bar.jog_line.update(self.jog_choice.describe(channel))

    def action_next_channel(self) -> None:
        """Make the next channel current."""
        if self.channels.row_count:
            self.channels.move_cursor(row=(self.channels.cursor_row + 1) % self.channels.row_count)

    # ------------------------------------------------------------ commands

    def check_action(self, action: str, parameters: tuple[object, ...]) -> bool | None:
        """While the program dialog is open its keys are text, not commands."""
        if (isinstance(self.screen, ProgramPicker | AlarmPage)
                and action not in self._DIALOG_ACTIONS):
            return False
        if self.focused is self.mdi and action not in self._DIALOG_ACTIONS:
            return False  # the MDI line has the keys: letters are text, not commands
        return True

    def _command(self, what: str, operation: Operation) -> None:
        client, channel = self.client, self.current_channel
        if client is None or channel is None:
            self.message.say(f"{what}: {text.unreachable(self.endpoint)}", error=True)
            return
        self.run_worker(self._report(what, operation(client, channel)), group="command")

    async def _report(self, what: str, operation: Awaitable[str]) -> None:
        try:
            line = await operation
        except AdsError as exc:  # refused or unanswered: a message, never a crash
            self.message.say(text.refused(what, exc, self.endpoint), error=True)
        else:
            self.message.say(line)

    def action_start(self) -> None:
        """START (also resumes after HOLD)."""
        self._command("START", control.start)

    def action_hold(self) -> None:
        """Feedhold."""
        self._command("HOLD", control.hold)

    def action_reset(self) -> None:
        """RESET (the service releases a held jog key itself)."""
        self.continuous_jog.forget()
        self._command("RESET", control.reset)

    def action_single_block(self) -> None:
        """Toggle single block."""
        self._command("single block", control.toggle_single_block)

    def action_override(self, step_01pct: int) -> None:
        """Feed override up or down by ``step_01pct`` (0.1 %)."""
        self._command("feed override",
                      lambda client, ch: control.step_override(client, ch, step_01pct))

    def action_suspend(self) -> None:
        """Toggle the jog-of-path suspension of the current channel's axis output."""
        self._command("suspend axis output", control.toggle_suspend)

    def action_jog(self, direction: int) -> None:
        """Jog the chosen axis one increment, or continuously while the key repeats
        (selects MANUAL; docs/manual.md)."""
        if self.jog_choice.continuous:
            self._command("jog", lambda client, ch: self.continuous_jog.press(
                client, ch, self.jog_choice, direction))
        else:
            self._command("jog", lambda client, ch: manual_keys.jog(
                client, ch, self.jog_choice, direction))

    def action_jog_release(self) -> None:
        """Release a continuous jog's key now."""
        self.run_worker(self._report("jog stop", self.continuous_jog.release()),
                        group="command")

    def action_jog_axis(self) -> None:
        """Choose the next axis of the current channel to jog."""
        if self.current_channel is not None:
            self.message.say(self.jog_choice.next_axis(self.current_channel))
            self.mode_bar.jog_line.update(self.jog_choice.describe(self.current_channel))

    def action_jog_increment(self) -> None:
        """Choose the next jog step (1 um .. 10 mm, continuous)."""
        self.message.say(self.jog_choice.next_increment())
        self.mode_bar.jog_line.update(self.jog_choice.describe(self.current_channel))

    # ------------------------------------------------------------ modes and MDI

    def action_select_mode(self, name: str) -> None:
        """Command the mode ``name`` (a ``ChannelMode`` name) in the current channel;
        MDI also puts the keys into the MDI line."""
        mode = ChannelMode[name]
        self._command("mode", lambda client, ch: select_mode(client, ch, mode))
        if mode is ChannelMode.MDI:
            self.mdi.focus()

    def on_mode_bar_chosen(self, event: ModeBar.Chosen) -> None:
        """A click on the mode bar."""
        self.action_select_mode(event.mode.name)

    def action_mdi(self) -> None:
        """Type a manual block (the MDI line gets the keys)."""
        self.mdi.focus()

    def on_input_submitted(self, event: Input.Submitted) -> None:
        """Enter in the MDI line: run it in the current channel; it joins the history."""
        if event.input is not self.mdi:
            return
        line = event.value.strip()
        if not line:
            return
        self.mdi.history.add(line)
        self.mdi.value = ""

        async def run(client: AsyncClient, channel: ChannelView) -> str:
            await client.mdi(blocks(line), channel.id)
            return f"ch{channel.id}: MDI {line}"

        self._command("manual block", run)

    def action_select_program(self) -> None:
        """Ask for a program (the store's NC programs) and select it in the current channel."""

        async def pick(client: AsyncClient, channel: ChannelView) -> str:
            names = [p.name for p in await client.programs()]
            name = await self.push_screen_wait(ProgramPicker(channel.id, names))
            if not name:
                return f"ch{channel.id}: no program selected"
            return await control.select_program(client, channel, name)

        self._command("select program", pick)

    def action_alarms(self) -> None:
        """The alarm page: active alarms and history, acknowledge (docs/alarms.md)."""
        self.push_screen(AlarmPage(self.alarm_line, self.client))

    # ------------------------------------------------------------ look-ahead

    def action_lookahead(self) -> None:
        """Show or hide the contour look-ahead panel (requests run only while shown)."""
        shown = not self.lookahead.display
        self.lookahead.display = shown
        if shown:
            self.run_worker(self._follow_lookahead(), name="lookahead", group="lookahead",
                            exclusive=True)
        else:
            self.workers.cancel_group(self, "lookahead")

    def action_lookahead_mode(self) -> None:
        """Switch between the elements ahead (mode 2) and the marked area (mode 1)."""
        self.lookahead_mode = (LookaheadMode.MARKED_AREA
                               if self.lookahead_mode is LookaheadMode.AHEAD
                               else LookaheadMode.AHEAD)
        self.message.say("contour look-ahead: " + (
            "the marked area (mode 1)" if self.lookahead_mode is LookaheadMode.MARKED_AREA
            else "the elements ahead (mode 2)"))
        self._lookahead_wake.set()

    async def _follow_lookahead(self) -> None:
        while True:
            self._lookahead_wake.clear()
            client, channel = self.client, self.current_channel
            if client is not None and channel is not None:
                try:
                    self.lookahead.show(await fetch(client, channel, self.lookahead_mode))
                except AdsError as exc:  # e.g. 0x701: this channel has no FCT_CONTOUR_LAH
                    self.lookahead.show_error(
                        channel, text.refused("contour look-ahead request", exc, self.endpoint))
            elif channel is not None:
                self.lookahead.show_error(channel, text.unreachable(self.endpoint))
            # Block ends wake the loop early, but a program of short blocks must not turn
            # the request into a busy loop: MIN_GAP_S first, then wait for a reason.
            await asyncio.sleep(MIN_GAP_S)
            with contextlib.suppress(TimeoutError):
                async with asyncio.timeout(REFRESH_S - MIN_GAP_S):
                    await self._lookahead_wake.wait()


cli = typer.Typer(add_completion=False)


@cli.command()
def run(
    endpoint: str = typer.Option(
        DEFAULT_ENDPOINT, "--endpoint", metavar="URL", envvar="CNC_ENDPOINT",
        help="Service endpoint (default: $CNC_ENDPOINT, else tcp://127.0.0.1:5555).",
    ),
    timeout_s: float = typer.Option(
        DEFAULT_TIMEOUT_S, "--timeout", metavar="S", min=0.01,
        help="Seconds without a reply before the service counts as unreachable.",
    ),
    key_file: str | None = key_option("The HMI's"),
    server_key: str | None = server_key_option(),
    mdi_history: str = typer.Option(
        str(default_history_file()), "--mdi-history", metavar="FILE",
        help="File that keeps the MDI history between sessions ('' keeps none).",
    ),
) -> None:
    """Terminal HMI of a cnc-objects service (keys: docs/hmi.md)."""
    try:
        client_curve(key_file or None, server_key or None)  # refused now, not in every retry
    except ClientValueError as exc:
        print(f"cnc-hmi: {exc}", file=sys.stderr)
        raise typer.Exit(2) from None
    HmiApp(endpoint, timeout_s, key_file or None, server_key or None,
           Path(mdi_history) if mdi_history else None).run()


def main(argv: list[str] | None = None) -> None:
    """Entry point of ``cnc-hmi`` (``argv``: the options, default the command line)."""
    cli(args=argv, prog_name="cnc-hmi")


if __name__ == "__main__":
    main()
