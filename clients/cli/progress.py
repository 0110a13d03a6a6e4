"""A progress bar for ``cnc upload`` and ``cnc download`` of a large program: on stderr, on
a terminal only (a pipe or a script gets the result line alone); rich is imported only
then."""

from __future__ import annotations

import sys
from collections.abc import Callable, Iterator
from contextlib import ExitStack, contextmanager

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


@contextmanager
def download_progress(what: str, min_bytes: int) -> Iterator[Progress | None]:
    """``upload_progress`` for a transfer whose size comes with its first report: the bar
    is drawn from the first ``progress(received_bytes, total_bytes)`` of a total over
    ``min_bytes`` (a one-frame download draws nothing and imports nothing)."""
    if not sys.stderr.isatty():
        yield None
        return
    with ExitStack() as stack:
        drawn: list[Progress | None] = []

        def progress(received: int, total: int) -> None:
            if not drawn:
                bar = stack.enter_context(upload_progress(what, total, min_bytes))
                drawn.append(bar)
            bar = drawn[0]
            if bar is not None:
                bar(received, total)

        yield progress
