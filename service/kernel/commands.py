"""Commands the service queues for the kernel; the cycle thread applies them.

A command is applied at the start of a cycle and answers None (done) or a ``Refusal``
that says why not. Kernel code knows nothing of ADS: the binding maps refusal reasons to
ADS return codes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any, ClassVar, Protocol

from .axis_params import update_axis
from .channel_mode import ChannelState
from .contour_lookahead import RequestError, check_request
from .kernel_state import KernelState
from .operator_switches import rapid_override_per_mille
from .refusal import Refusal as Refusal  # the commands' answer, imported from here too
from .refusal import RefusalReason as RefusalReason
from .state import ExecutionMode


class Command(Protocol):
    """Anything the cycle thread can apply to the kernel state."""

    def apply(self, state: KernelState) -> Refusal | None:
        """Change ``state``; return None when done, a Refusal otherwise."""
        ...


#: Execution mode bits the kernel implements. Others are refused, never stored.
IMPLEMENTED_EXECUTION_MODES = (
    ExecutionMode.ISG_STANDARD | ExecutionMode.SYNCHK | ExecutionMode.PROD_TIME
    | ExecutionMode.MACHINE_LOCK | ExecutionMode.ADD_MDI_BLOCK
    | ExecutionMode.SUPPRESS_TECHNO_OUTPUT
)
_KNOWN_MODE_BITS = sum(m for m in ExecutionMode)


def execution_mode_refused(value: int) -> Refusal | None:
    """Why ``value`` cannot be an execution mode of this kernel, or None."""
    if value < 0 or value & ~_KNOWN_MODE_BITS:
        return Refusal(
            RefusalReason.INVALID_VALUE,
            f"execution mode 0x{value & 0xFFFFFFFF:x} has bits that are not execution modes",
        )
    missing = value & ~IMPLEMENTED_EXECUTION_MODES
    if missing:
        names = "|".join(m.name for m in ExecutionMode if m and m & missing and m.name)
        return Refusal(
            RefusalReason.INVALID_VALUE,
            f"execution mode {names} (0x{missing:x}) is not implemented by this kernel; "
            "it has SYNCHK 0x8, PROD_TIME 0x10, MACHINE_LOCK 0x40, ADD_MDI_BLOCK 0x80 and "
            "SUPPRESS_TECHNO_OUTPUT 0x2000",
        )
    if value & ExecutionMode.SYNCHK and value & ExecutionMode.PROD_TIME:
        return Refusal(RefusalReason.INVALID_VALUE,
                       "SYNCHK and PROD_TIME cannot be combined: choose the syntax check or "
                       "the machining time calculation")
    return None


@dataclass(frozen=True, slots=True)
class SetFeedOverride:
    """Command the channel's feed override (0.1 %); in effect from this cycle."""

    channel_index: int
    value: int

    def apply(self, state: KernelState) -> Refusal | None:
        channel = state.channels[self.channel_index]
        if not 0 <= self.value <= channel.switches.feed_override_max:
            return Refusal(
                RefusalReason.INVALID_VALUE,
                f"feed override {self.value / 10:g} % is outside "
                f"0..{channel.switches.feed_override_max / 10:g} %",
            )
        channel.switches = replace(channel.switches, feed_override_command=self.value,
                                   feed_override_per_mille=self.value)
        channel.switches = replace(  # G0 may follow the feed override
            channel.switches, rapid_override_per_mille=rapid_override_per_mille(channel))
        return None


@dataclass(frozen=True, slots=True)
class SetExecutionMode:
    """The HMI commands the channel's execution mode (``mc_command_execution_mode_w``,
    the control unit's ``request_r``); it takes effect at the next program start."""

    channel_index: int
    value: int

    def apply(self, state: KernelState) -> Refusal | None:
        refused = execution_mode_refused(self.value)
        if refused is None:
            channel = state.channels[self.channel_index]
            channel.switches = replace(channel.switches, execution_mode_command=self.value)
        return refused


@dataclass(frozen=True, slots=True)
class SetExecutionModePlc:
    """``decoder_mc_control.execution_mode.command_w``: the PLC's execution mode."""

    channel_index: int
    value: int

    def apply(self, state: KernelState) -> Refusal | None:
        refused = execution_mode_refused(self.value)
        if refused is None:
            channel = state.channels[self.channel_index]
            channel.switches = replace(channel.switches, execution_mode_plc_command=self.value)
        return refused


@dataclass(frozen=True, slots=True)
class SetExecutionModeEnable:
    """``decoder_mc_control.execution_mode.enable_w``: TRUE makes the next program start
    take the PLC's ``command_w`` instead of the HMI's request."""

    channel_index: int
    value: bool

    def apply(self, state: KernelState) -> Refusal | None:
        channel = state.channels[self.channel_index]
        channel.switches = replace(channel.switches, execution_mode_plc_enable=bool(self.value))
        return None


@dataclass(frozen=True, slots=True)
class SetSyntaxCheckParameter:
    """``ch<c>.syn_chk.<name>`` (P-CHAN-00019/20/28/416) for the next syntax check."""

    channel_index: int
    name: str
    value: int

    def apply(self, state: KernelState) -> Refusal | None:
        channel = state.channels[self.channel_index]
        value = self.value
        if self.name in ("errors_total", "errors_per_block") and not 0 <= value <= 0xFFFF:
            return Refusal(RefusalReason.INVALID_VALUE,
                           f"syn_chk.{self.name} {value} is outside 0..65535")
        if self.name in ("interactive", "record_result"):
            value = bool(value)
        syn_chk = channel.switches.syn_chk.model_copy(update={self.name: value})
        channel.switches = replace(channel.switches, syn_chk=syn_chk)
        return None


@dataclass(frozen=True, slots=True)
class SetSingleBlock:
    """Single block on or off; in effect from this cycle."""

    channel_index: int
    value: bool

    def apply(self, state: KernelState) -> Refusal | None:
        channel = state.channels[self.channel_index]
        channel.switches = replace(channel.switches, single_block=bool(self.value))
        return None


@dataclass(frozen=True, slots=True)
class SetProdTimeTrace:
    """``ch<c>.prod_time_trace``: the next PROD_TIME run records its path (for plots)."""

    channel_index: int
    value: bool

    def apply(self, state: KernelState) -> Refusal | None:
        channel = state.channels[self.channel_index]
        channel.switches = replace(channel.switches, prod_time_trace=bool(self.value))
        return None


@dataclass(frozen=True, slots=True)
class SelectMode:
    """Select the channel's operation mode (ChannelMode value)."""

    channel_index: int
    value: int

    def apply(self, state: KernelState) -> Refusal | None:
        return state.runners[self.channel_index].select_mode(self.value)


@dataclass(frozen=True, slots=True)
class SelectProgram:
    """Select a program of the store for AUTOMATIC."""

    channel_index: int
    value: str

    def apply(self, state: KernelState) -> Refusal | None:
        return state.runners[self.channel_index].select_program(self.value)


@dataclass(frozen=True, slots=True)
class ChannelPulse:
    """A command object written with TRUE to trigger ``method`` of the channel runner
    (the subclasses made by ``_pulse`` name the method)."""

    channel_index: int
    value: bool
    method: ClassVar[str] = ""

    def apply(self, state: KernelState) -> Refusal | None:
        if not self.value:
            return None  # writing FALSE is accepted and does nothing, as a PLC edge
        answer: Refusal | None = getattr(state.runners[self.channel_index], self.method)()
        return answer


def _pulse(name: str, method: str) -> type[ChannelPulse]:
    """The ``ChannelPulse`` that triggers ``method`` of the channel runner."""
    return type(name, (ChannelPulse,), {
        "__slots__": (), "method": method, "__qualname__": name,
        "__doc__": f"Write TRUE: ``ChannelRunner.{method}``.",
    })


StartProgram = _pulse("StartProgram", "start")
Feedhold = _pulse("Feedhold", "hold")
ResetChannel = _pulse("ResetChannel", "reset")


@dataclass(frozen=True, slots=True)
class ManualBlock:
    """Run NC text as manual blocks (MDI)."""

    channel_index: int
    value: str

    def apply(self, state: KernelState) -> Refusal | None:
        return state.runners[self.channel_index].manual_block(self.value)


def _suspend_refused(
    state: KernelState, channel_index: int, command: bool, enable: bool
) -> Refusal | None:
    """Suspending the axis output is not possible while the channel is in error."""
    channel = state.channels[channel_index]
    wants = command if enable else channel.suspend.request_r
    if wants and not channel.suspend.output_suspended and channel.state == ChannelState.ERROR:
        return Refusal(
            RefusalReason.NOT_READY,
            f"channel {channel.channel_id} is in error: its axis output cannot be suspended; "
            "clear the error (RESET) and try again",
        )
    return None


@dataclass(frozen=True, slots=True)
class SetSuspendCommand:
    """``suspend_axis_output.command_w``: TRUE asks to suspend the channel's axis output."""

    channel_index: int
    value: bool

    def apply(self, state: KernelState) -> Refusal | None:
        channel = state.channels[self.channel_index]
        refused = _suspend_refused(state, self.channel_index, bool(self.value),
                                   channel.suspend.enable_w)
        if refused is None:
            channel.suspend = replace(channel.suspend, command_w=bool(self.value))
        return refused


@dataclass(frozen=True, slots=True)
class SetSuspendEnable:
    """``suspend_axis_output.enable_w``: TRUE makes the CNC follow ``command_w``."""

    channel_index: int
    value: bool

    def apply(self, state: KernelState) -> Refusal | None:
        channel = state.channels[self.channel_index]
        refused = _suspend_refused(state, self.channel_index, channel.suspend.command_w,
                                   bool(self.value))
        if refused is None:
            channel.suspend = replace(channel.suspend, enable_w=bool(self.value))
        return refused


@dataclass(frozen=True, slots=True)
class UpdateAxisParameters:
    """Change one axis's parameters from an axis parameter list (its clones keep theirs).

    ``changes`` is the parsed list; ``problem`` the reader's report when it could not
    be parsed (then nothing changes). Takes effect at the next program start.
    """

    changes: dict[str, Any] | None
    problem: str = ""

    def apply(self, state: KernelState) -> Refusal | None:
        if self.changes is None:
            return Refusal(RefusalReason.INVALID_VALUE, self.problem)
        updated, why = update_axis(state.axis_params, self.changes)
        if updated is None:
            return Refusal(RefusalReason.INVALID_VALUE, why)
        state.axis_params[updated.logical_number] = updated
        return None


@dataclass(frozen=True, slots=True)
class SetContourRequest:
    """Write ``request.start_position`` or ``request.length`` of the contour look-ahead
    control unit (stored; read when the PLC sets the semaphore)."""

    channel_index: int
    field: str  # "start_position" or "length"
    value: float

    def apply(self, state: KernelState) -> Refusal | None:
        if not math.isfinite(self.value):
            return Refusal(RefusalReason.INVALID_VALUE,
                           f"request.{self.field} must be a finite number, not {self.value}")
        channel = state.channels[self.channel_index]
        match self.field:
            case "start_position":
                channel.contour = replace(channel.contour, request_start_position=self.value)
            case "length":
                channel.contour = replace(channel.contour, request_length=self.value)
            case _:
                raise ValueError(f"no contour request field {self.field!r}")
        return None


@dataclass(frozen=True, slots=True)
class SetContourSemaphore:
    """``semaphor_rw``: TRUE asks the CNC to answer the request (the CNC fills the
    response and resets it to FALSE before the write is acknowledged)."""

    channel_index: int
    value: bool

    def apply(self, state: KernelState) -> Refusal | None:
        channel = state.channels[self.channel_index]
        runner = state.runners[self.channel_index]
        unit = channel.contour
        if not self.value:
            channel.contour = replace(unit, semaphor=False)
            return None
        if not runner.config.contour_lookahead:
            return Refusal(
                RefusalReason.NOT_SUPPORTED,
                f"contour look-ahead is not enabled in channel {channel.channel_id}: add "
                "FCT_CONTOUR_LAH to its interpolator_function (P-CHAN-00650)",
            )
        try:
            check_request(unit.request_start_position, unit.request_length)
        except RequestError as exc:
            return Refusal(RefusalReason.INVALID_VALUE, str(exc))
        channel.contour = replace(unit, semaphor=True)
        runner.answer_contour_request()
        return None


@dataclass(frozen=True, slots=True)
class AcknowledgeAlarm:
    """``alarm_acknowledge_w``: acknowledge the alarm with this sequence number."""

    value: int

    def apply(self, state: KernelState) -> Refusal | None:
        return state.alarms.acknowledge(self.value)


@dataclass(frozen=True, slots=True)
class AcknowledgeAllAlarms:
    """``alarm_acknowledge_all_w``: TRUE acknowledges every active alarm; FALSE does
    nothing (a PLC may write the bit back)."""

    value: bool

    def apply(self, state: KernelState) -> Refusal | None:
        if self.value:
            state.alarms.acknowledge_all()
        return None
