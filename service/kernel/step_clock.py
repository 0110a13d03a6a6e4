"""The step clock: kernel time advances only when a client grants cycles.

A test (or a PLC under test) writes ``cnc_cycle_step_w`` = N: the kernel runs N cycles
back to back, one at a time, and answers the write after the N-th cycle is published,
so a read sent after the reply sees exactly that cycle. While no cycles are granted,
nothing runs: the kernel applies every other command at once, between cycles, and
publishes the result without a cycle passing, so a PLC's acknowledge written between
two steps returns without waiting for a step (``Kernel._run_stepped``). Like the
virtual clock it is deterministic: GEO waits for the decoder, so a run gives the same
result cycle by cycle however the steps are cut.
"""

from __future__ import annotations

from dataclasses import dataclass

from .clock import WakeSource
from .refusal import Refusal, RefusalReason
from .state import CycleStats

#: The most cycles one write of ``cnc_cycle_step_w`` may grant (``[limits]
#: step_max_cycles``): the write's reply waits for all of them.
STEP_MAX_CYCLES = 100_000


@dataclass(frozen=True, slots=True)
class StepCycles:
    """``cnc_cycle_step_w``: run ``cycles`` cycles now, answered after the last one is
    published. Applied by the cycle thread's step loop; refused under any other clock."""

    cycles: int


#: the refusal of a step under a clock that does not step
NOT_STEPPING = Refusal(
    RefusalReason.NOT_READY,
    "cnc_cycle_step_w steps the kernel only under --clock step; this service runs on "
    "another clock",
)
#: the refusal of a step written while another step's cycles run
STEP_RUNNING = Refusal(
    RefusalReason.BUSY,
    "cnc_cycle_step_w: another step's cycles are running; write again after its reply",
)


class StepClock:
    """Runs no cycle by itself: ``Kernel._run_stepped`` runs the granted cycles back to
    back, so there is no deadline (``lateness`` None) and nothing to wait for."""

    def __init__(self, cycle_s: float, max_cycles: int = STEP_MAX_CYCLES) -> None:
        self.cycle_s = cycle_s
        self.max_cycles = max_cycles
        self.lateness = None  # no deadlines: kernel time is cycles x cycle time

    def start(self) -> None:
        """Nothing to prepare: kernel time starts at cycle 0."""

    def wait(self, busy: bool, stats: CycleStats, wake: WakeSource) -> None:
        """Granted cycles run back to back: no waiting between them."""

    def check(self, step: StepCycles) -> Refusal | None:
        """The refusal of a step outside 1..``max_cycles`` (ADS 0x706), else None."""
        if 1 <= step.cycles <= self.max_cycles:
            return None
        return Refusal(
            RefusalReason.INVALID_VALUE,
            f"cnc_cycle_step_w grants 1 to {self.max_cycles} cycles "
            f"([limits] step_max_cycles), not {step.cycles}",
        )
