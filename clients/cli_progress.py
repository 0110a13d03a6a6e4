"""A progress bar for ``cnc upload`` of a large program: on stderr, on a terminal only
(a pipe or a script gets the result line alone); rich is imported only then."""

from __future__ import annotations

import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager

Progress = Callable[[int, int], None]


@contextmanager
def upload_progress(what: str, total_bytes: int, min_bytes: int) -> Iterator[Progress | None]:
    """A ``progress(sent_bytes, total_bytes)`` callback that draws a bar of ``what`` on
    stderr while the block runs; None when stderr is no terminal or the upload is
    smaller than ``min_bytes`` (one frame: nothing to watch)."""
    if total_bytes <= min_bytes or not sys.stderr.isatty():
        yield None
        return
    from rich.console import Console
    from rich.progress import (
        BarColumn,
        DownloadColumn,
        Progress,
        TextColumn,
        TimeRemainingColumn,
        TransferSpeedColumn,
    )

    bar = Progress(TextColumn("{task.description}"), BarColumn(), DownloadColumn(),
                   TransferSpeedColumn(), TimeRemainingColumn(),
                   console=Console(stderr=True), transient=True)
    task = bar.add_task(what, total=total_bytes)
    with bar:
        yield lambda sent, total: bar.update(task, completed=sent, total=total)
