"""cnc-service started as its entry point in tests, with its output."""

from __future__ import annotations

import os
import subprocess
import sys

# Rich draws usage errors in a box as wide as the terminal: wide enough for one line.
_WIDE = {**os.environ, "COLUMNS": "200"}


def run_service(*args: str) -> subprocess.CompletedProcess:
    """``cnc-service *args`` in the working directory, to its end."""
    return subprocess.run(
        [sys.executable, "-m", "cnc_objects.service.main", *args], capture_output=True,
        text=True, timeout=30, env=_WIDE,
    )
