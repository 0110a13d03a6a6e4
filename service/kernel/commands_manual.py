"""Commands of manual mode and homing: one per writable object of an axis.

Each is applied by the cycle thread like every command (``commands.Command``) and hands
its value to the channel's ``ManualMode``; the answer is None or a ``Refusal``.
"""

from __future__ import annotations

from dataclasses import dataclass

from .commands import Refusal
from .kernel_state import KernelState
from .manual_mode import ManualMode


@dataclass(frozen=True, slots=True)
class ManualAxisCommand:
    """A write to a manual-mode object of one axis: ``action`` names what it does."""

    channel_index: int
    axis_index: int
    action: str  # one of the cases of ``apply``
    value: int | bool

    def apply(self, state: KernelState) -> Refusal | None:
        manual: ManualMode = state.runners[self.channel_index].manual
        k, value = self.axis_index, self.value
        match self.action:
            case "operation_mode":
                return manual.set_operation_mode(k, int(value))
            case "increment":
                return manual.set_increment(k, int(value))
            case "resolution":
                return manual.set_resolution(k, int(value))
            case "rapid":
                return manual.set_rapid(k, bool(value))
            case "jog_plus":
                return manual.jog(k, +1, bool(value))
            case "jog_minus":
                return manual.jog(k, -1, bool(value))
            case "handwheel":
                return manual.handwheel(k, int(value))
            case "homing_start":
                return manual.start_homing(k) if value else None
        raise ValueError(f"unknown manual action {self.action!r}")  # a binding bug
