"""A data table with fixed columns and rows that wait for their first values."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, Protocol

from rich.text import Text
from textual.widgets import DataTable


class Keyed(Protocol):
    """A row's view: its key in the table."""

    @property
    def key(self) -> str:
        """The row's key."""
        ...


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

    def cell(self, row: Keyed | str, column: str) -> str:
        """The text shown for ``row`` (a view, or its key) in ``column``."""
        key = row if isinstance(row, str) else row.key
        return str(self.get_cell(key, column))

    def _setter(self, row: str) -> Callable[[str, Callable[[Any], str]], Callable[[Any], None]]:
        """``column(key, show)``: a feed's callback that shows ``show(value)`` in ``row``."""
        def column(key: str, show: Callable[[Any], str]) -> Callable[[Any], None]:
            # Text, not str: a str cell is parsed as markup, and names may hold brackets
            return lambda value: self.update_cell(row, key, Text(show(value)))
        return column
