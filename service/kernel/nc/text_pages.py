"""The physical lines of one NC file, in memory or read from its file page by page.

A program as CAM writes it has 10 to 500 MB; its lines as Python strings take four
times that. So a program in the store is read as a stream (``SourceText.open``): the
file is cut into *pages* of about ``PAGE_BYTES`` that end at a line end, and the decoder
sees the lines of one page at a time (``window``). What it costs:

* **Opening** reads the file once, at C speed (``bytes.count``, ``bytes.find``): the
  byte offset and first line of each page (the page index, two integers per page, 3 200
  pages for 200 MB), the ``%`` header lines and ``#COMMENT BEGIN/END`` lines (the
  sections need them before decoding starts) and whether the file is UTF-8 (else it is
  CP1252, ISG's encoding, as ``ProgramStore.read_text`` decides). Measured: about 0.2 s
  per 100 MB.
* **Reading** a line outside the pages in memory loads its page: one ``pread``, one
  decode, one split. The ``PAGES_KEPT`` pages read last stay in memory, so a loop or a
  ``$GOTO`` back into them reads nothing again; any other line costs one page read (a
  backward ``$GOTO`` in a huge program, a loop body longer than the pages kept).
* **Memory** is the page index plus ``PAGES_KEPT`` pages of lines, whatever the size of
  the file (a line longer than a page makes its page as long as the line).

The file stays open (one descriptor) until ``close``, so a program replaced in the store
while it runs goes on from the content it started with. A text given as a string (a
manual block, a test) is one page held whole.
"""

from __future__ import annotations

import os
import re
import weakref
from bisect import bisect_right
from collections.abc import Iterable
from itertools import accumulate
from operator import add
from pathlib import Path

# "#COMMENT BEGIN" / "#COMMENT END" at the start of a line (any case, any spacing)
_COMMENT_DIRECTIVE = re.compile(r"[ \t]*#[ \t]*COMMENT[ \t]+(BEGIN|END)\b", re.IGNORECASE)
PAGE_BYTES = 128 * 1024  # bytes read at once, cut back to the last line end
PAGES_KEPT = 8  # pages of lines kept in memory (the ones read last)
_BOM = b"\xef\xbb\xbf"  # a UTF-8 byte order mark: 3 bytes before the first line, not code

#: a program as the kernel's loader gives it: the text, or the file to read as a stream
NcText = str | Path


def comment_directive(line: str) -> str | None:
    """"BEGIN" or "END" when ``line`` is ``#COMMENT BEGIN`` / ``#COMMENT END``."""
    if "#" not in line:
        return None
    m = _COMMENT_DIRECTIVE.match(line)
    return m.group(1).upper() if m else None


class Window:
    """Lines ``first``..``stop``-1 of a text in memory, with the byte offset of each."""

    __slots__ = ("first", "stop", "lines", "offsets")

    def __init__(self, first: int, lines: list[str], offsets: list[int]) -> None:
        self.first = first
        self.stop = first + len(lines)
        self.lines = lines
        self.offsets = offsets


class SourceText:
    """One NC file: its name, its number of lines, each line and its byte offset.

    ``SourceText(text, name)`` holds ``text`` whole; ``SourceText.open(path, name)``
    reads the file page by page (see the module's docstring).
    """

    _fd = -1  # the open file of a streamed text
    _closer: weakref.finalize[[int], SourceText] | None = None  # closes it when collected

    def __init__(self, text: str, name: str) -> None:
        self.name = name
        base = 0
        if text.startswith("\ufeff"):  # a UTF-8 byte order mark is 3 bytes, not code
            text = text[1:]
            base = 3
        raw = text.split("\n")
        if text.isascii():
            lengths: Iterable[int] = map(len, raw)
        else:  # offsets are byte offsets of the UTF-8 file, as the HMI counts them
            lengths = (len(line.encode("utf-8")) for line in raw)
        # byte offset of line i: the lengths before it plus the i newlines
        offsets = list(map(add, accumulate(lengths, initial=base), range(len(raw))))
        if "\r" in text:
            raw = [line[:-1] if line.endswith("\r") else line for line in raw]
        self.count = len(raw)
        self._window = Window(0, raw, offsets)
        self._marked = _marked_in_text(text, raw)
        self._fd = -1
        self._page_offsets: list[int] = []
        self._page_firsts: list[int] = []
        self._pages: dict[int, Window] = {}
        self._encoding = "utf-8"

    @classmethod
    def open(cls, path: Path, name: str, page_bytes: int | None = None) -> SourceText:
        """The file at ``path``, read as a stream in pages of about ``page_bytes``
        (default ``PAGE_BYTES``); ``OSError`` when it cannot be read."""
        fd = os.open(path, os.O_RDONLY)
        src = cls.__new__(cls)
        src.name = name
        src._fd = fd
        closer = src._closer = weakref.finalize(src, os.close, fd)
        try:
            scan = _Scan(fd, max(1, PAGE_BYTES if page_bytes is None else page_bytes))
            src._encoding = "utf-8" if scan.utf8 else "cp1252"
            src._page_offsets = scan.page_offsets  # one more: the end of the file
            src._page_firsts = scan.page_firsts
            src.count = scan.lines
            src._marked = [(n, raw if isinstance(raw, str) else _decode(raw, src._encoding))
                           for n, raw in scan.marked]
            src._pages = {}
            src._window = src._load(0)
        except BaseException:
            closer()
            raise
        return src

    def close(self) -> None:
        """Close the file (a streamed text); lines already in memory stay readable.
        A text not closed closes its file when it is collected."""
        if self._closer is not None:
            self._closer()  # once: a finalizer runs at most one time
            self._fd = -1

    def window(self, index: int) -> Window:
        """The page of lines that holds line ``index`` (0-based, < ``count``)."""
        w = self._window
        if w.first <= index < w.stop or not self._page_firsts:
            return w
        k = bisect_right(self._page_firsts, index) - 1
        kept = self._pages.pop(k, None)
        w = kept if kept is not None else self._load(k)
        self._pages[k] = w  # the newest last: the oldest goes first
        if len(self._pages) > PAGES_KEPT:
            del self._pages[next(iter(self._pages))]
        self._window = w
        return w

    def line(self, index: int) -> str:
        """Physical line ``index`` (0-based), without its line end."""
        w = self._window
        if not w.first <= index < w.stop:
            w = self.window(index)
        return w.lines[index - w.first]

    def offset(self, index: int) -> int:
        """Byte offset of the start of line ``index``."""
        w = self._window
        if not w.first <= index < w.stop:
            w = self.window(index)
        return w.offsets[index - w.first]

    def marked_lines(self) -> list[tuple[int, str]]:
        """(index, text) of the lines whose first non-blank is ``%`` and of the
        ``#COMMENT BEGIN``/``END`` lines, in order: what the sections are made of."""
        return self._marked

    def _load(self, k: int) -> Window:
        """Page ``k`` of the file, read and split into lines."""
        start = self._page_offsets[k]
        data = os.pread(self._fd, self._page_offsets[k + 1] - start, start)
        text = _decode(data, self._encoding)
        raw = text.split("\n")
        if k + 1 < len(self._page_firsts):  # it ends with a line end: no line after it
            raw.pop()
        lengths: Iterable[int] = map(len, raw) if data.isascii() else map(len, data.split(b"\n"))
        offsets = list(map(add, accumulate(lengths, initial=start), range(len(raw))))
        if "\r" in text:
            raw = [line[:-1] if line.endswith("\r") else line for line in raw]
        return Window(self._page_firsts[k], raw, offsets)


def _decode(data: bytes, encoding: str) -> str:
    return data.decode(encoding, errors="replace")


class _Scan:
    """The one pass over a file when it is opened: pages, line count, marked lines,
    encoding."""

    def __init__(self, fd: int, page_bytes: int) -> None:
        self.page_offsets: list[int] = []
        self.page_firsts: list[int] = []
        self.marked: list[tuple[int, str | bytes]] = []
        self.utf8 = True
        pos = 3 if os.pread(fd, 3, 0) == _BOM else 0
        line = 0
        carry = b""
        want = page_bytes
        while True:
            chunk = os.pread(fd, want, pos + len(carry))
            data = carry + chunk if carry else chunk
            cut = data.rfind(b"\n") + 1 if chunk else len(data)
            if chunk and cut == 0:  # a line longer than a page: read more at once
                carry = data
                want *= 2
                continue
            want = page_bytes
            page = data[:cut]
            self.page_offsets.append(pos)
            self.page_firsts.append(line)
            self._look(page, line)
            line += page.count(b"\n")
            pos += cut
            carry = data[cut:]
            if not chunk:  # the last page: the line after the last line end
                break
        self.page_offsets.append(pos)
        self.lines = line + 1
        self.marked.sort(key=lambda m: m[0])

    def _look(self, page: bytes, first: int) -> None:
        """Encoding and marked lines of one page (``first``: its first line)."""
        if self.utf8 and not page.isascii():
            try:
                page.decode("utf-8")
            except UnicodeDecodeError:
                self.utf8 = False
        for mark in (b"%", b"#"):
            counted_to = 0  # newlines before ``counted_to`` are in ``line``
            line = first
            found = page.find(mark)
            while found >= 0:
                start = page.rfind(b"\n", 0, found) + 1
                end = page.find(b"\n", found)
                if end < 0:
                    end = len(page)
                if not page[start:found].strip(b" \t"):  # the mark begins the line
                    line += page.count(b"\n", counted_to, start)
                    counted_to = start
                    raw = page[start:end].rstrip(b"\r")
                    if mark == b"%":
                        self.marked.append((line, raw))
                    else:  # ASCII keywords: latin-1 reads them whatever the encoding
                        text = raw.decode("latin-1")
                        if comment_directive(text) is not None:
                            self.marked.append((line, text))
                found = page.find(mark, end)  # the next line: one mark per line counts


def _marked_in_text(text: str, lines: list[str]) -> list[tuple[int, str]]:
    """``SourceText.marked_lines`` of a text in memory (``str.find``: fast on big texts)."""
    starts = []
    for mark in "%#":
        pos = text.find(mark)
        while pos >= 0:
            line_start = text.rfind("\n", 0, pos) + 1
            if not text[line_start:pos].strip(" \t"):
                starts.append(line_start)
            pos = text.find(mark, pos + 1)
    starts.sort()
    marked = []
    line_no = 0
    last = 0
    for start in starts:
        line_no += text.count("\n", last, start)
        last = start
        raw = lines[line_no]
        if raw.lstrip().startswith("%") or comment_directive(raw) is not None:
            marked.append((line_no, raw))
    return marked
