"""The program selection dialog: type a name, or pick one of the program store's NC programs.

The store also holds user cycles (``*.ecy``, called by a program, never selected) and
whatever else an admin uploaded (the files the kernel writes are in the output area, not
here). The list shows what a channel can run: names ending in ``.nc`` (any case) and
names without a suffix. A name typed into the input is selected
as typed, listed or not.
"""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import PurePath
from typing import Any

from textual.binding import Binding
from textual.containers import Vertical
from textual.screen import ModalScreen
from textual.widgets import Input, Label, OptionList

NC_PROGRAM_SUFFIXES = frozenset({".nc", ""})  # "" = no suffix (``SUB``, ``L SUB``)


def nc_programs(names: Iterable[str]) -> list[str]:
    """The NC programs among the store's file names, in the given order."""
    return [n for n in names if PurePath(n).suffix.lower() in NC_PROGRAM_SUFFIXES]


class ProgramPicker(ModalScreen[str | None]):
    """Returns the chosen program name, or None when cancelled (escape)."""

    BINDINGS = [Binding("escape", "cancel", "Cancel")]
    DEFAULT_CSS = """
    ProgramPicker { align: center middle; }
    ProgramPicker > Vertical {
        width: 60; height: auto; max-height: 24; border: round $accent; background: $surface;
    }
    ProgramPicker OptionList { height: auto; max-height: 16; }
    """

    def __init__(self, channel_id: int, files: Iterable[str]) -> None:
        super().__init__()
        self.channel_id = channel_id
        self.programs = nc_programs(files)

    def compose(self) -> Any:
        """A prompt, the name input and the store's NC programs (filtered by the input)."""
        with Vertical():
            yield Label(f"Program for channel {self.channel_id} (enter selects, esc cancels)")
            yield Input(placeholder="program name", id="program-name")
            yield OptionList(*self.programs, id="program-list")

    def on_input_changed(self, event: Input.Changed) -> None:
        """Narrow the list to the names that contain what was typed."""
        options = self.query_one(OptionList)
        options.clear_options()
        options.add_options([p for p in self.programs if event.value.lower() in p.lower()])

    def on_input_submitted(self, event: Input.Submitted) -> None:
        """Enter in the input: that name (or the only one the filter left)."""
        name = event.value.strip()
        matches = [p for p in self.programs if name.lower() in p.lower()]
        if name not in self.programs and len(matches) == 1:
            name = matches[0]
        self.dismiss(name or None)

    def on_option_list_option_selected(self, event: OptionList.OptionSelected) -> None:
        """Enter on a listed program."""
        self.dismiss(str(event.option.prompt))

    def action_cancel(self) -> None:
        """Leave without selecting."""
        self.dismiss(None)
