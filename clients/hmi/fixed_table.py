"""A data table with fixed columns and rows that wait for their first values."""

from __future__ import annotations

from rich.text import Text
from textual.widgets import DataTable


class FixedColumnsTable(DataTable[str | Text]):
    """``COLUMNS`` (key, header, width) are added at mount with fixed widths, so that the
    widths do not jump while values change; a new row shows "…" until its values come."""

    COLUMNS: tuple[tuple[str, str, int], ...] = ()

    def on_mount(self) -> None:
        for key, label, width in self.COLUMNS:
            self.add_column(label, key=key, width=width)

    def add_waiting_row(self, label: str, key: str) -> None:
        """A row labelled ``label`` whose other cells wait for the feeds."""
        self.add_row(label, *("…" for _ in self.COLUMNS[1:]), key=key)
