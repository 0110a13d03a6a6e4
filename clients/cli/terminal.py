"""Where ``cnc`` prints: stdout or stderr, as plain text, without importing rich.

``Terminal.print`` takes the arguments of ``rich.console.Console.print`` that the commands
use. Plain text (``markup=False``, or no ``[`` in it; no ``:`` when ``emoji`` is left on;
no ``style``) is written as is, which is what rich would write for it; anything else, and
every other attribute of a console (``is_terminal``, ``width``), goes to a rich
``Console``, made on first use. So a command that prints plain lines
(read, write, status, every JSON line) never imports rich, which costs more than a
command's own work at start-up (docs/design-notes.md, "A quick cnc").
"""

from __future__ import annotations

import sys
from typing import TYPE_CHECKING, Any, TextIO

if TYPE_CHECKING:
    from rich.console import Console


class Terminal:
    """stdout (``stderr=False``) or stderr, printed to as by a rich ``Console(highlight=
    False, soft_wrap=True)``: the text whole, never wrapped, flushed after each print."""

    def __init__(self, stderr: bool) -> None:
        self._stderr = stderr
        self._rich: Console | None = None

    @property
    def stream(self) -> TextIO:
        """The stream now (looked up at each print: a test or a caller may swap it)."""
        return sys.stderr if self._stderr else sys.stdout

    def print(self, text: object = "", *, end: str = "\n", markup: bool = True,
              emoji: bool = True, highlight: bool = False, style: str | None = None,
              **rich_options: Any) -> None:
        """Print ``text`` then ``end``; markup, emoji codes and a style as rich does."""
        line = str(text)
        plain = (style is None and not highlight and not rich_options
                 and not (markup and "[" in line) and not (emoji and ":" in line))
        if not plain:
            self._console().print(line, end=end, markup=markup, emoji=emoji,
                                  highlight=highlight, style=style, **rich_options)
            return
        stream = self.stream
        stream.write(line + end)
        stream.flush()

    def __getattr__(self, name: str) -> Any:
        """Everything else a rich ``Console`` has (``is_terminal``, ``width``, ...), from the
        console made on first use."""
        if name.startswith("_"):
            raise AttributeError(name)
        return getattr(self._console(), name)

    def _console(self) -> Console:
        if self._rich is None:
            from rich.console import Console  # only for markup and styles

            self._rich = Console(stderr=self._stderr, highlight=False, soft_wrap=True)
        return self._rich
