"""Commands of the PLC and HMI for the technology output and the spindle."""

from __future__ import annotations

from dataclasses import dataclass

from .commands import Refusal, RefusalReason
from .kernel_state import KernelState


@dataclass(frozen=True, slots=True)
class AcknowledgeTechnoUnit:
    """The PLC acknowledges ``techno_unit_std_sync[index]`` of a channel (``command_w``
    TRUE; FALSE changes nothing: the PLC may clear its own flag)."""

    channel_index: int
    index: int
    value: bool = True

    def apply(self, state: KernelState) -> Refusal | None:
        if not self.value:
            return None
        runner = state.runners[self.channel_index]
        why = runner.plc.acknowledge(self.index)
        if why is not None:
            return Refusal(RefusalReason.INVALID_VALUE, why)
        return None


@dataclass(frozen=True, slots=True)
class SetSpindleOverride:
    """Command the spindle override of a channel (0.1 %)."""

    channel_index: int
    value: int

    def apply(self, state: KernelState) -> Refusal | None:
        runner = state.runners[self.channel_index]
        why = runner.plc.spindle.set_override(self.value)
        if why is not None:
            return Refusal(RefusalReason.INVALID_VALUE, why)
        return None
