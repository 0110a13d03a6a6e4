"""Helpers for the decoder tests: decode a text, expect an error."""

from __future__ import annotations

from collections.abc import Mapping

import pytest

from cnc_objects.service.kernel.nc import Block, Decoder, ModalState, NcError

AXES = ("X", "Y", "Z")
TOOLS = {1: 2.5, 2: 1.0}


def loader_of(files: Mapping[str, str] | None):
    """A program store: ``loader(name)`` returns the text or raises KeyError."""
    files = dict(files or {})

    def loader(name: str) -> str:
        return files[name]

    return loader


def decoder(text: str, *, files: Mapping[str, str] | None = None, axes=AXES,
            tools=TOOLS, modal: ModalState | None = None, manual: bool = False,
            skip_levels: int = 1, file: str = "prog.nc", axis_numbers=None,
            contour_lookahead: bool = False) -> Decoder:
    """A Decoder with the test defaults."""
    return Decoder(text, file, axes=axes, loader=loader_of(files), tools=tools,
                   modal=modal, skip_levels=skip_levels, manual=manual,
                   axis_numbers=axis_numbers, contour_lookahead=contour_lookahead)


def decode(text: str, **kw) -> list[Block]:
    """All blocks of ``text``."""
    return list(decoder(text, **kw).blocks())


def motions(text: str, **kw) -> list:
    """The Motion of every block that has one."""
    return [b.motion for b in decode(text, **kw) if b.motion is not None]


def ends(text: str, **kw) -> list[tuple[float, ...]]:
    """End points of all motions."""
    return [m.end_mm for m in motions(text, **kw)]


def error_of(text: str, **kw) -> NcError:
    """The NcError decoding ``text`` raises."""
    with pytest.raises(NcError) as info:
        decode(text, **kw)
    return info.value


def slow(text: str) -> str:
    """The same program with every line forced through the general parser.

    An empty ``( )`` comment at the end of a line changes nothing for the general path
    but keeps the line away from the fast path's regular expression.
    """
    out = []
    for line in text.split("\n"):
        code, sep, comment = line.partition(";")
        out.append(code + "()" + sep + comment if code.strip() else line)
    return "\n".join(out)
