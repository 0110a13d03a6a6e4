"""The syntax check in kernel tests: a recorder of what the check reports, and a run of it."""

from __future__ import annotations

import dataclasses

from cnc_objects.service.kernel.nc import (
    Block,
    Decoder,
    MotionKind,
    NcError,
    StopKind,
)
from cnc_objects.service.kernel.nc.check import CheckAborted, ErrorCategory, PointBatch


class Recorder:
    """The kernel's side of the check: records what the decoder reports; after
    ``errors_total`` errors (P-CHAN-00019, 0: no limit) it aborts the check."""

    def __init__(self, errors_per_block: int = 0, line_by_line: bool = False,
                 errors_total: int = 0) -> None:
        self.errors_per_block = errors_per_block
        self.line_by_line = line_by_line
        self.errors_total = errors_total
        self.errors: list[tuple[NcError, ErrorCategory]] = []
        self.lines: list[tuple[str, int, int]] = []  # (file, index, after) of line()

    def report(self, error: NcError, category: ErrorCategory) -> None:
        assert isinstance(error, NcError) and isinstance(category, ErrorCategory)
        self.errors.append((error, category))
        if self.errors_total and len(self.errors) >= self.errors_total:
            raise CheckAborted(f"{len(self.errors)} errors")

    def line(self, src, index: int, after: int) -> None:
        assert after > index
        self.lines.append((src.name, index, after))

    @property
    def found(self) -> list[tuple[int, int, ErrorCategory]]:
        """(id, line, category) of every reported error, in order."""
        return [(int(e.id), e.line, cat) for e, cat in self.errors]


@dataclasses.dataclass
class Run:
    check: Recorder
    items: list  # Blocks and PointBatches as yielded
    decoder: Decoder

    @property
    def blocks(self) -> list[Block]:
        return [item for item in self.items if isinstance(item, Block)]

    @property
    def batches(self) -> list[PointBatch]:
        return [item for item in self.items if isinstance(item, PointBatch)]

    def points(self) -> list[tuple[str, int, MotionKind, tuple, tuple | None]]:
        """(file, line, kind, end point, arc centre) of every motion, records and
        Blocks alike, in decoding order."""
        out = []
        for item in self.items:
            if isinstance(item, PointBatch):
                for index, kind, end, centre in item.records:
                    out.append((item.src.name, index + 1, kind, end, centre))
            elif item.motion is not None:
                m = item.motion
                out.append((item.source.file, item.source.line, m.kind, m.end_mm, m.center_mm))
        return out

    def ends(self) -> list[tuple[float, ...]]:
        return [p[3] for p in self.points()]

    def end_of_line(self, line: int) -> tuple[float, ...] | None:
        """End point of the motion of ``line`` of the main file (None: no motion)."""
        found = [p[3] for p in self.points() if p[1] == line and p[0] == "prog.nc"]
        assert len(found) <= 1
        return found[0] if found else None

    def ended(self) -> bool:
        """Decoding reached M30/M2: the last item is the program end Block."""
        last = self.items[-1] if self.items else None
        return isinstance(last, Block) and last.stop == StopKind.PROGRAM_END
