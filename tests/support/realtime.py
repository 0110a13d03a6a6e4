"""Whether this machine lets the cycle thread run under SCHED_FIFO."""

from __future__ import annotations

import subprocess
import sys

_PROBE = """
import os
try:
    os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param({priority}))
    print("granted")
except OSError:
    print("refused")
"""


def fifo_permitted(priority: int, wrapper: tuple[str, ...] = ()) -> bool:
    """Whether a process started like the service may run SCHED_FIFO at ``priority``."""
    out = subprocess.run([*wrapper, sys.executable, "-c", _PROBE.format(priority=priority)],
                         capture_output=True, text=True, check=True, timeout=30)
    return out.stdout.strip() == "granted"
