"""What a process costs, read from /proc (Linux)."""

from __future__ import annotations

import os
from pathlib import Path


def rss_kib(pid: int) -> int:
    """Resident memory of process ``pid`` in KiB (``VmRSS`` of /proc/<pid>/status)."""
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1])
    raise RuntimeError(f"/proc/{pid}/status has no VmRSS line")


def cpu_s(pid: int) -> float:
    """CPU time (user + system) process ``pid`` has used so far, in seconds: what a piece
    of its work costs, whatever else the machine runs (/proc/<pid>/stat)."""
    stat = Path(f"/proc/{pid}/stat").read_text()
    fields = stat[stat.rindex(")") + 2:].split()  # after "pid (comm) "
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def thread_count(pid: int) -> int:
    """Threads of process ``pid`` (entries of /proc/<pid>/task)."""
    return sum(1 for _ in Path(f"/proc/{pid}/task").iterdir())
