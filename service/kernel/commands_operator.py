"""Commands of the operator's switches: rapid override, skip levels (the HMI's and the
PLC's control unit), optional stop. What they mean is in ``operator_switches``."""

from __future__ import annotations

from dataclasses import dataclass, replace

from .kernel_state import KernelState
from .operator_switches import RAPID_OVERRIDE_MAX, rapid_override_per_mille, skip_mask_refused
from .refusal import Refusal, RefusalReason


@dataclass(frozen=True, slots=True)
class SetRapidOverride:
    """Command the channel's rapid override (0.1 %); in effect from this cycle."""

    channel_index: int
    value: int

    def apply(self, state: KernelState) -> Refusal | None:
        ch = state.channels[self.channel_index]
        if not 0 <= self.value <= RAPID_OVERRIDE_MAX:
            return Refusal(RefusalReason.INVALID_VALUE,
                           f"rapid override {self.value / 10:g} % is outside "
                           f"0..{RAPID_OVERRIDE_MAX / 10:g} %")
        ch.switches = replace(ch.switches, rapid_override_command=self.value)
        ch.switches = replace(ch.switches, rapid_override_per_mille=rapid_override_per_mille(ch))
        return None


@dataclass(frozen=True, slots=True)
class SetBlockIgnore:
    """Command the skip levels (bit n-1 skips lines ``/n``); from the next program start."""

    channel_index: int
    value: int

    def apply(self, state: KernelState) -> Refusal | None:
        refused = skip_mask_refused(self.value)
        if refused is None:
            ch = state.channels[self.channel_index]
            ch.switches = replace(ch.switches, block_ignore_command=self.value)
        return refused


@dataclass(frozen=True, slots=True)
class SetBlockIgnorePlc:
    """``decoder_mc_control.program_block_ignore.command_w``: the PLC's skip levels."""

    channel_index: int
    value: int

    def apply(self, state: KernelState) -> Refusal | None:
        refused = skip_mask_refused(self.value)
        if refused is None:
            ch = state.channels[self.channel_index]
            ch.switches = replace(ch.switches, block_ignore_plc_command=self.value)
        return refused


@dataclass(frozen=True, slots=True)
class SetBlockIgnorePlcEnable:
    """``decoder_mc_control.program_block_ignore.enable_w``: TRUE, the next program
    start takes the PLC's ``command_w`` instead of the HMI's request."""

    channel_index: int
    value: bool

    def apply(self, state: KernelState) -> Refusal | None:
        ch = state.channels[self.channel_index]
        ch.switches = replace(ch.switches, block_ignore_plc_enable=bool(self.value))
        return None


@dataclass(frozen=True, slots=True)
class SetM01StopEnable:
    """Switch the optional stop: TRUE, M1 stops; FALSE, the path runs through M1."""

    channel_index: int
    value: bool

    def apply(self, state: KernelState) -> Refusal | None:
        ch = state.channels[self.channel_index]
        ch.switches = replace(ch.switches, m01_stop_enable=bool(self.value))
        return None
