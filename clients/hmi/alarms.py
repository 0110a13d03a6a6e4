"""The HMI's alarms: an alarm line (the newest active alarm, always in view) and an alarm
page (the active alarms and the history, with acknowledge), docs/alarms.md.

Both follow ``alarm_changes_r``: each change re-reads the lists (``AsyncClient.alarms``).
The page acknowledges the alarm under the cursor (enter or ``k``) or all (``K``); the
service refuses an unknown number with a sentence, shown on the page.
"""

from __future__ import annotations

from typing import Any

from textual.binding import Binding
from textual.containers import Vertical
from textual.screen import ModalScreen
from textual.widgets import DataTable, Label, Static

from cnc_objects.clients.alarm_ops import AlarmInfo, AlarmList
from cnc_objects.clients.client import AsyncClient
from cnc_objects.clients.errors import AdsError
from cnc_objects.protocol.alarm_values import AlarmState

from .. import names
from .session import Feed

COLUMNS = ("#", "state", "severity", "id", "ch", "time", "where", "text")


def alarm_line_text(listed: AlarmList | None) -> str:
    """What the alarm line says: the newest active alarm and how many more there are."""
    if listed is None or not listed.active:
        return "no active alarms"
    newest = listed.active[0]
    more = listed.active_count - 1
    return f"alarm {newest}" + (f"  (+{more} more: key e)" if more else "")


class AlarmLine(Static):
    """One line: the newest active alarm; in the error colour while one is unacknowledged."""

    DEFAULT_CSS = """
    AlarmLine { height: 1; padding: 0 1; }
    AlarmLine.unacknowledged { background: $error 60%; color: $text; }
    AlarmLine.acknowledged { background: $warning 30%; }
    """

    def __init__(self, **kwargs: Any) -> None:
        super().__init__("no active alarms", markup=False, **kwargs)  # texts hold brackets
        self.listed: AlarmList | None = None
        self.text = "no active alarms"
        self.page: AlarmPage | None = None  # the open page, refreshed with the line

    def feeds(self, client: AsyncClient) -> list[Feed]:
        """The subscription that keeps the line (and an open page) current."""
        async def apply(_changes: int) -> None:
            try:
                self.show(await client.alarms(history=True))
            except AdsError as exc:  # a service without alarm objects: say so, go on
                self.text = f"alarms not available: {exc}"
                self.update(self.text)

        return [Feed(names.alarm_changes_r, apply)]

    def show(self, listed: AlarmList) -> None:
        """Show ``listed``'s newest active alarm; refresh an open page."""
        self.listed = listed
        self.text = alarm_line_text(listed)
        waiting = any(a.state == AlarmState.ACTIVE for a in listed.active)
        self.set_class(waiting, "unacknowledged")
        self.set_class(bool(listed.active) and not waiting, "acknowledged")
        self.update(self.text)
        if self.page is not None:
            self.page.load(listed)


def _row(alarm: AlarmInfo) -> tuple[str, ...]:
    return (str(alarm.sequence), alarm.state.name.lower(), alarm.severity_name, str(alarm.id),
            str(alarm.channel), alarm.time.strftime("%H:%M:%S"), alarm.where, alarm.text)


class AlarmPage(ModalScreen[None]):
    """The active alarms (newest first) and the history; acknowledge with the keys."""

    BINDINGS = [
        Binding("escape,A", "close", "Close"),
        Binding("k", "acknowledge", "Acknowledge"),
        Binding("K", "acknowledge_all", "Acknowledge all"),
    ]
    DEFAULT_CSS = """
    AlarmPage { align: center middle; }
    AlarmPage > Vertical { width: 100%; height: 90%; border: round $error; background: $surface; }
    AlarmPage DataTable { height: 1fr; }
    AlarmPage #alarm-status { height: 1; }
    """

    def __init__(self, line: AlarmLine, client: AsyncClient | None) -> None:
        super().__init__()
        self.line = line
        self.client = client
        self.status = Static("", markup=False, id="alarm-status")
        self.active: DataTable[str] = DataTable(id="alarm-active", cursor_type="row")
        self.history: DataTable[str] = DataTable(id="alarm-history", cursor_type="row")

    def compose(self) -> Any:
        """Active alarms, history, a status line."""
        with Vertical():
            yield Label("active alarms (enter/k acknowledges, K all, esc closes)")
            yield self.active
            yield Label("history (newest first)")
            yield self.history
            yield self.status

    def on_mount(self) -> None:
        """Fill the tables from what the line knows; the line refreshes them."""
        for table in (self.active, self.history):
            table.add_columns(*COLUMNS)
        self.line.page = self
        if self.line.listed is not None:
            self.load(self.line.listed)
        self.active.focus()

    def on_unmount(self) -> None:
        """The line stops refreshing the page."""
        self.line.page = None

    def load(self, listed: AlarmList) -> None:
        """Show ``listed``; the cursor stays on its row number."""
        for table, alarms in ((self.active, listed.active), (self.history, listed.history)):
            row = table.cursor_row
            table.clear()
            for alarm in alarms:
                table.add_row(*_row(alarm), key=str(alarm.sequence))
            if alarms:
                table.move_cursor(row=min(row, len(alarms) - 1))

    def selected_sequence(self) -> int | None:
        """The sequence number of the active alarm under the cursor."""
        if not self.active.row_count:
            return None
        return int(self.active.get_row_at(self.active.cursor_row)[0])

    def say(self, line: str) -> None:
        """Show ``line`` on the page's status line."""
        self.status.update(line)

    async def action_acknowledge(self) -> None:
        """Acknowledge the alarm under the cursor."""
        sequence = self.selected_sequence()
        if sequence is None:
            self.say("no active alarm to acknowledge")
            return
        await self._act(f"alarm #{sequence} acknowledged",
                        lambda c: c.acknowledge_alarm(sequence))

    async def on_data_table_row_selected(self, event: DataTable.RowSelected) -> None:
        """Enter on an active alarm (the table takes the key before the page)."""
        if event.data_table is self.active:
            await self.action_acknowledge()

    async def action_acknowledge_all(self) -> None:
        """Acknowledge every active alarm."""
        await self._act("every active alarm acknowledged", lambda c: c.acknowledge_all_alarms())

    async def _act(self, done: str, request: Any) -> None:
        if self.client is None:
            self.say("not connected")
            return
        try:
            await request(self.client)
        except AdsError as exc:  # refused (role, unknown number) or unanswered
            self.say(f"refused: {exc}")
        else:
            self.say(done)

    def action_close(self) -> None:
        """Back to the main screen."""
        self.dismiss(None)
