"""What the cycle tests share: a decoder with its surroundings (program store that
also takes written files, message list, HSC parameters), error places by text."""

from __future__ import annotations

from typing import Any

import pytest

from cnc_objects.service.kernel.nc import Decoder, ModalState, NcError, NcErrorId
from cnc_objects.service.kernel.nc.blocks import Block
from cnc_objects.service.kernel.nc.technology import Surroundings
from cnc_objects.service.kernel.path.kinematics import Kinematics

AXES = ("X", "Y", "Z")
FIVE_AXES = ("X", "Y", "Z", "A", "C")  # --machine five-axis-ac's channel 1
TOOLS = {1: 2.5, 9: 4.0}


class Channel:
    """What surrounds a decoder: the program store (also the store #MSG SAVE and the
    cycles write into), the message list, the HSC channel parameters; with
    ``kinematics`` a five-axis channel (X Y Z A C)."""

    def __init__(self, files: dict[str, str] | None = None, *, hscs: dict[str, Any] | None = None,
                 kinematics: Kinematics | None = None) -> None:
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

    def decoder(self, text: str, *, modal: ModalState | None = None, check: Any = None,
                manual: bool = False) -> Decoder:
        axes = AXES if self.kinematics is None else FIVE_AXES
        return Decoder(text, "prog.nc", axes=axes, loader=self.load, tools=TOOLS,
                       modal=modal, manual=manual, check=check,
                       surroundings=Surroundings(write_file=self.write_file,
                                                 show_message=self.messages.append,
                                                 hscs=self.hscs,
                                                 kinematic_chain=self.kinematics))

    def run(self, text: str, **kw: Any) -> tuple[Decoder, list[Block]]:
        d = self.decoder(text, **kw)
        return d, list(d.blocks())

    def moves(self, text: str, **kw: Any) -> tuple[Decoder, list[Block]]:
        d, blocks = self.run(text, **kw)
        return d, [b for b in blocks if b.motion is not None]

    def error(self, text: str, **kw: Any) -> NcError:
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
