"""The program panel: the text of the current channel's program, its current line marked.

The text comes from the program store (``AsyncClient.download``) when a channel selects
a program (``mc_active_program_name_r``) or runs another file (``mc_active_file_name_r``:
a subprogram, a cycle); the current line is ``mc_active_line_r``, the line of the block
in execution, so the mark follows a running program block by block. The panel shows
``WINDOW_LINES`` lines around it, with line numbers. Manual blocks (file ``MDI``) and a
file that is not in the store are named instead of shown.
"""

from __future__ import annotations

from collections.abc import Awaitable, Callable
from dataclasses import dataclass
from typing import Any

from rich.text import Text
from textual.widgets import Static

from cnc_objects.clients.client import AsyncClient
from cnc_objects.clients.errors import AdsConnectionError, AdsError, AdsTimeoutError

from .machine import ChannelView, Machine
from .session import Feed

WINDOW_LINES = 9  # lines shown: the current one in the middle where the text allows
CURRENT_STYLE = "reverse bold"
MDI_FILE_NAME = "MDI"  # the file name the kernel gives manual blocks (mc_active_file_name_r)


@dataclass(slots=True)
class ChannelProgram:
    """What one channel runs: program selected, file and line in execution (1 = first)."""

    program: str = ""
    file: str = ""
    line: int = 0

    @property
    def shown_file(self) -> str:
        """The file whose text is shown: the one in execution, else the selected one."""
        return self.file or self.program


def window(line_count: int, current: int, size: int = WINDOW_LINES) -> range:
    """The 1-based line numbers to show: ``size`` lines with ``current`` in the middle,
    moved inwards at the text's start and end."""
    first = max(1, min(current - size // 2, line_count - size + 1))
    return range(first, min(line_count, first + size - 1) + 1)


class ProgramView(Static):
    """The current channel's program text, the current line highlighted."""

    DEFAULT_CSS = "ProgramView { height: auto; border: round $accent 50%; padding: 0 1; }"

    def __init__(self, **kwargs: Any) -> None:
        super().__init__("", markup=False, **kwargs)
        self.programs: dict[str, ChannelProgram] = {}  # per channel key
        self.texts: dict[str, list[str] | str] = {}  # per file: lines, or why none
        self.current = ""  # key of the channel shown
        self.highlighted = ""  # the text of the highlighted line ("" when none)
        self._client: AsyncClient | None = None

    def feeds(self, client: AsyncClient, machine: Machine) -> list[Feed]:
        """Per channel: program name, file name and line in execution."""
        self._client = client
        self.texts = {}  # a new session: the store may have changed meanwhile
        self.programs = {ch.key: ChannelProgram() for ch in machine.channels}
        feeds: list[Feed] = []
        for ch in machine.channels:
            feeds += [Feed(ch.obj("mc_active_program_name_r"), self._program(ch)),
                      Feed(ch.obj("mc_active_file_name_r"), self._file(ch)),
                      Feed(ch.obj("mc_active_line_r"), self._line(ch))]
        return feeds

    def show_channel(self, channel: ChannelView) -> None:
        """Show the program of ``channel`` (the current one)."""
        self.current = channel.key
        self._render_current()

    @property
    def shown(self) -> ChannelProgram:
        """What the current channel runs."""
        return self.programs.get(self.current, ChannelProgram())

    def _program(self, channel: ChannelView) -> Callable[[str], Awaitable[None]]:
        async def apply(name: str) -> None:
            self.texts.pop(name, None)  # selected again: perhaps uploaded anew
            self.programs[channel.key].program = name
            await self._fetch(self.programs[channel.key].shown_file)
            self._render_if(channel)
        return apply

    def _file(self, channel: ChannelView) -> Callable[[str], Awaitable[None]]:
        async def apply(name: str) -> None:
            self.programs[channel.key].file = name
            await self._fetch(name)
            self._render_if(channel)
        return apply

    def _line(self, channel: ChannelView) -> Callable[[int], None]:
        def apply(line: int) -> None:
            self.programs[channel.key].line = line
            self._render_if(channel)
        return apply

    async def _fetch(self, name: str) -> None:
        if not name or name in self.texts or self._client is None:
            return
        if name == MDI_FILE_NAME:
            self.texts[name] = "manual blocks (MDI): no program text; the MDI line has them"
            return
        try:
            data = await self._client.download(name)
        except (AdsTimeoutError, AdsConnectionError):
            raise  # the session is lost: the session loop handles it
        except AdsError as exc:  # e.g. a manual block: no file in the store
            self.texts[name] = f"{name}: no text in the program store ({exc})"
            return
        self.texts[name] = data.decode("utf-8", errors="replace").splitlines()

    def _render_if(self, channel: ChannelView) -> None:
        if channel.key == self.current:
            self._render_current()

    def _render_current(self) -> None:
        shown = self.shown
        name = shown.shown_file
        lines = self.texts.get(name)
        self.border_title = (f"{self.current} program {name or '-'}"
                             + (f", line {shown.line}" if shown.line else ""))
        self.highlighted = ""
        if not name:
            self.update("no program selected (p)")
            return
        if not isinstance(lines, list):
            self.update(lines or f"{name}: reading …")
            return
        rendered = Text()
        for number in window(len(lines), shown.line):
            current = number == shown.line
            marker = "▶" if current else " "
            rendered.append(f"{marker}{number:5d}  {lines[number - 1]}\n",
                            style=CURRENT_STYLE if current else "")
            if current:
                self.highlighted = lines[number - 1]
        rendered.rstrip()
        self.update(rendered)
