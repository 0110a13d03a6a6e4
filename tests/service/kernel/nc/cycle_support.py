"""What the cycle tests share: a decoder with its surroundings (program store that
also takes written files, message list, HSC parameters), error places by text."""

from __future__ import annotations

import pytest

from cnc_objects.service.kernel.nc import Decoder, NcError, NcErrorId
from cnc_objects.service.kernel.nc.blocks import Block
from cnc_objects.service.kernel.nc.technology import Surroundings

AXES = ("X", "Y", "Z")
TOOLS = {1: 2.5, 9: 4.0}


class Channel:
    """What surrounds a decoder: the program store (also the store #MSG SAVE and the
    cycles write into), the message list, the HSC channel parameters."""

    def __init__(self, files=None, *, hscs=None, kinematics: bool = False) -> None:
        self.files: dict[str, str] = dict(files or {})
        self.messages: list[str] = []
        self.writes: list[tuple[str, str, bool]] = []
        self.hscs = dict(hscs or {})
        self.kinematics = kinematics

    def load(self, name: str) -> str:
        return self.files[name]  # KeyError when missing

    def write_file(self, name: str, text: str, replace: bool) -> None:
        self.writes.append((name, text, replace))
        self.files[name] = text if replace else self.files.get(name, "") + text

    def decoder(self, text: str, *, modal=None, check=None, manual: bool = False) -> Decoder:
        return Decoder(text, "prog.nc", axes=AXES, loader=self.load, tools=TOOLS,
                       modal=modal, manual=manual, check=check,
                       surroundings=Surroundings(write_file=self.write_file,
                                                 show_message=self.messages.append,
                                                 hscs=self.hscs, kinematics=self.kinematics))

    def run(self, text: str, **kw) -> tuple[Decoder, list[Block]]:
        d = self.decoder(text, **kw)
        return d, list(d.blocks())

    def moves(self, text: str, **kw) -> tuple[Decoder, list[Block]]:
        d, blocks = self.run(text, **kw)
        return d, [b for b in blocks if b.motion is not None]

    def error(self, text: str, **kw) -> NcError:
        with pytest.raises(NcError) as info:
            self.run(text, **kw)
        return info.value


def where(text: str, needle: str, occurrence: int = 0) -> tuple[int, int]:
    """1-based (line, column) of the ``occurrence``-th ``needle`` in ``text``."""
    index = -1
    for _ in range(occurrence + 1):
        index = text.index(needle, index + 1)
    line = text.count("\n", 0, index) + 1
    column = index - (text.rfind("\n", 0, index) + 1) + 1
    return line, column


def assert_at(error: NcError, err_id: NcErrorId, text: str, needle: str,
              occurrence: int = 0, *, file: str = "prog.nc") -> None:
    """``error`` has ``err_id`` and points at the ``occurrence``-th ``needle``."""
    assert error.id == err_id, error
    assert error.file == file
    assert (error.line, error.column) == where(text, needle, occurrence), error
