"""The listing of the program store and of the output area (ADS Read at their LIST
offsets): one line per file, ``name<TAB>size_bytes<TAB>mtime_unix_s\\n``, UTF-8, sorted
by name. The service encodes it, clients decode it; both use this module."""

from __future__ import annotations

from collections.abc import Iterable


def encode_listing(files: Iterable[tuple[str, int, float]]) -> bytes:
    """``(name, size_bytes, mtime_unix_s)`` of each file as the listing's bytes."""
    return "".join(f"{name}\t{size}\t{mtime:.3f}\n" for name, size, mtime in files).encode(
        "utf-8")


def decode_listing(raw: bytes) -> list[tuple[str, int, float]]:
    """The ``(name, size_bytes, mtime_unix_s)`` of each line; ValueError for a line that
    is not of the form."""
    files = []
    for line in raw.decode("utf-8").splitlines():
        name, size, mtime = line.split("\t")
        files.append((name, int(size), float(mtime)))
    return files
