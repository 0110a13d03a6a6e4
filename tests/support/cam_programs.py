"""CAM-like finishing programs of any size, made on the fly (deterministic).

A CAM finishing program is mostly short straight moves: here 0.05 mm steps in X along
rows 0.1 mm apart in Y, with Z stepping between 0 and -0.96 mm, at F3000, numbered, in
the hot path's canonical form (``N<n> X.. Y.. Z..``): about 27 bytes and 1 ms of
machining per line.
"""

from __future__ import annotations

from pathlib import Path

HEADER = b"%cam\nN1 G90 G17 G1 F3000\n"
END = b"M30\n"
_LINES_PER_WRITE = 10_000


def cam_lines(first: int, count: int) -> bytes:
    """Lines ``first``..``first + count - 1`` of the moves (line k is ``N<k + 2>``)."""
    return b"".join(b"N%d X%.3f Y%.3f Z%.3f\n" % (
        k + 2, (k * 0.05) % 400, (k // 8000) * 0.1, -(k % 97) * 0.01)
        for k in range(first, first + count))


def write_cam_program(path: Path, size_bytes: int, last_line: bytes = END) -> int:
    """Write a program of at least ``size_bytes`` to ``path``, ending with ``last_line``
    (M30 by default); the number of lines before ``last_line``."""
    with path.open("wb") as f:
        f.write(HEADER)
        total = len(HEADER)
        n = 0
        while total < size_bytes:
            chunk = cam_lines(n, _LINES_PER_WRITE)
            f.write(chunk)
            n += _LINES_PER_WRITE
            total += len(chunk)
        f.write(last_line)
    return HEADER.count(b"\n") + n
