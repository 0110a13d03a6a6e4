"""The message line: what the last command did, or why it could not."""

from __future__ import annotations

from typing import Any

from textual.widgets import Static


class MessageLine(Static):
    """One line above the key bindings; errors in the error colour."""

    DEFAULT_CSS = """
    MessageLine { height: 1; padding: 0 1; background: $panel; }
    MessageLine.error { background: $error 40%; color: $text; }
    """

    def __init__(self, **kwargs: Any) -> None:
        super().__init__("", markup=False, **kwargs)  # service texts may hold brackets
        self.text = ""
        self.is_error = False

    def say(self, line: str, *, error: bool = False) -> None:
        """Show ``line`` (replaces the one before)."""
        self.text, self.is_error = line, error
        self.set_class(error, "error")
        self.update(line)
