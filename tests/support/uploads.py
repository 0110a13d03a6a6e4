"""Programs for upload tests: a G1 program of a given size, and what a store leaves behind."""

from __future__ import annotations

import hashlib
from pathlib import Path


def g1_program(size_bytes: int) -> bytes:
    """A CAM-like finishing program of about ``size_bytes``: numbered G1 moves."""
    lines = [b"%cam\nG90 G17 F1200\n"]
    n, total = 0, 0
    while total < size_bytes:
        n += 1
        line = b"N%d G1 X%.3f Y%.3f Z%.3f\n" % (n, (n * 0.013) % 400, (n * 0.007) % 300,
                                                -((n % 97) * 0.01))
        lines.append(line)
        total += len(line)
    lines.append(b"M30\n")
    return b"".join(lines)


def leftovers(service_dir: Path) -> list[str]:
    """Temporary files of uploads in the store's directory."""
    return sorted(p.name for p in service_dir.iterdir() if p.name.startswith("."))


def write_big_program(path: Path, megabytes: int = 200) -> bytes:
    """A CAM-sized program of about ``megabytes`` MB written to ``path`` a block of 1 MB
    at a time (never whole in memory); its SHA-256."""
    block = g1_program(1_000_000)
    digest = hashlib.sha256()
    with path.open("wb") as f:
        for k in range(megabytes):
            part = b"(block %d)\n" % k + block
            f.write(part)
            digest.update(part)
    return digest.digest()


def peak_rss_bytes(pid: int) -> int:
    """The peak resident memory of process ``pid`` (VmHWM)."""
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmHWM:"):
            return int(line.split()[1]) * 1024
    raise AssertionError(f"no VmHWM for process {pid}")
