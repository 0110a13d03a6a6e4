"""Reading what a child process (a client the test kills) says on its stdout."""

from __future__ import annotations

import selectors
import subprocess


def read_line(process: subprocess.Popen[str], timeout_s: float) -> str:
    """The process' next stdout line within ``timeout_s`` (its exit fails the test)."""
    with selectors.DefaultSelector() as selector:
        selector.register(process.stdout, selectors.EVENT_READ)  # type: ignore[arg-type]
        if not selector.select(timeout_s):
            raise AssertionError(f"the child said nothing within {timeout_s:g} s")
    line = process.stdout.readline().strip()  # type: ignore[union-attr]
    assert line, f"the child ended with {process.wait()}"
    return line
