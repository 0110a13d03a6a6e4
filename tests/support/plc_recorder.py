"""The PLC's side of M/H/S/T output in kernel tests: what was output, in order, and the
synchronisation kinds."""

from __future__ import annotations

from typing import Any

from cnc_objects.service.kernel.state import Snapshot
from tests.support.kernel import KernelHarness

KINDS = {"10": "MOS", "11": "MVS_SVS", "12": "MVS_SNS", "13": "MNS_SNS", "14": "NO_SYNCH"}


class Recorder:
    """Every published snapshot, in order (the kernel's cycle-end hook)."""

    def __init__(self, h: KernelHarness) -> None:
        self.rows: list[Snapshot] = []
        self._next = h.kernel.on_cycle_end  # the harness's own hook keeps working
        h.kernel.on_cycle_end = self._add

    def _add(self, s: Snapshot) -> None:
        self.rows.append(s)
        if self._next is not None:
            self._next(s)

    def first(self, predicate: Any) -> Snapshot:
        return next(s for s in list(self.rows) if predicate(s))
