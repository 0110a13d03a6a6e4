"""MDI entry: one input line for manual blocks, with a history that up/down recall.

``e`` focuses the input (F3, MDI mode, does too); enter runs the line as manual blocks
in the current channel (``AsyncClient.mdi``: the block selects MDI when the channel is
idle); a literal ``\\n`` separates blocks, as in ``cnc mdi``. Escape leaves the input.

Every entered line goes to the history (a repeat of the newest is not stored twice): up
recalls older entries, down newer ones, and down past the newest returns to what was
being typed. The history is kept for the session and, when the HMI has a history file,
saved there after each entry and read at start: one entry per line, the newest last, at
most ``HISTORY_MAX`` entries. ``cnc-hmi`` keeps it in ``default_history_file()``
(``$XDG_STATE_HOME/cnc-objects/mdi-history``, else ``~/.local/state/…``).
"""

from __future__ import annotations

import logging
import os
from pathlib import Path
from typing import Any

from textual.binding import Binding
from textual.widgets import Input

log = logging.getLogger(__name__)

HISTORY_MAX = 200  # entries kept (older ones are dropped from the file too)
HISTORY_NAME = "mdi-history"


def default_history_file() -> Path:
    """Where ``cnc-hmi`` keeps the MDI history: the user's state directory (XDG)."""
    state = os.environ.get("XDG_STATE_HOME") or str(Path.home() / ".local" / "state")
    return Path(state) / "cnc-objects" / HISTORY_NAME


def blocks(line: str) -> str:
    """The manual blocks of an entered line (``\\n`` typed as two characters separates)."""
    return line.replace("\\n", "\n")


class MdiHistory:
    """Entered lines, oldest first, and the recall position of up/down."""

    def __init__(self, file: Path | None = None) -> None:
        self.file = file
        self.entries: list[str] = self._load()
        self._position = len(self.entries)  # len = not recalling: the draft
        self._draft = ""

    def _load(self) -> list[str]:
        if self.file is None or not self.file.exists():
            return []
        try:
            lines = self.file.read_text(encoding="utf-8").splitlines()
        except OSError as exc:  # an unreadable file loses the history, not the HMI
            log.warning("MDI history %s not read: %s", self.file, exc)
            return []
        return [line for line in lines if line.strip()][-HISTORY_MAX:]

    def add(self, line: str) -> None:
        """Remember ``line`` (the newest); saved to the file when there is one."""
        if line.strip() and (not self.entries or self.entries[-1] != line):
            self.entries = [*self.entries, line][-HISTORY_MAX:]
            self._save()
        self._position, self._draft = len(self.entries), ""

    def _save(self) -> None:
        if self.file is None:
            return
        try:
            self.file.parent.mkdir(parents=True, exist_ok=True)
            self.file.write_text("".join(f"{e}\n" for e in self.entries), encoding="utf-8")
        except OSError as exc:  # a read-only home keeps the history for the session
            log.warning("MDI history %s not saved: %s", self.file, exc)

    def older(self, typed: str) -> str:
        """Up: the entry before the one shown (``typed``: what the input holds)."""
        if self._position == len(self.entries):
            self._draft = typed
        self._position = max(0, self._position - 1)
        return self.entries[self._position] if self.entries else typed

    def newer(self) -> str:
        """Down: the entry after the one shown; past the newest, the draft."""
        self._position = min(len(self.entries), self._position + 1)
        if self._position == len(self.entries):
            return self._draft
        return self.entries[self._position]


class MdiInput(Input):
    """The MDI line; up/down recall the history, escape gives the keys back to the app."""

    DEFAULT_CSS = "MdiInput.-textual-compact { padding: 0 1; }"
    BINDINGS = [
        Binding("up", "older", "Older", show=False),
        Binding("down", "newer", "Newer", show=False),
        Binding("escape", "leave", "Leave MDI", show=False),
    ]

    def __init__(self, history: MdiHistory, **kwargs: Any) -> None:
        super().__init__(placeholder="MDI: e to type a manual block, enter runs it, "
                                     "↑/↓ history, esc leaves", compact=True, **kwargs)
        self.history = history

    def action_older(self) -> None:
        """Recall the previous entry."""
        self._show(self.history.older(self.value))

    def action_newer(self) -> None:
        """Recall the next entry (or the draft)."""
        self._show(self.history.newer())

    def action_leave(self) -> None:
        """Back to the channel table (its keys are the app's commands)."""
        self.app.query_one("#channels").focus()

    def _show(self, line: str) -> None:
        self.value = line
        self.cursor_position = len(line)
