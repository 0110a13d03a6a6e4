"""Why a channel stands: the wait reason the GEO cycle computes for ``mc_wait_reason_r``.

Two levels, as ISG keeps them apart: the channel (ERROR waits for RESET, HOLD for START,
a start for its axes) and the path of a run (``path_wait_reason``: what the
interpolator waits for at a block end, override 0, a path without blocks). The first
reason that applies wins, in the order of ``channel_wait_reason``: the one an operator
must act on first. Both functions only read state the cycle has at hand (a few
attribute reads), so the reason costs next to nothing per cycle.
"""

from __future__ import annotations

from cnc_objects.protocol.values import WORKING_STATES
from cnc_objects.protocol.wait_reasons import WaitReason as WaitReason  # re-exported for the runs

from .channel_mode import ChannelMode, ChannelState
from .nc.blocks import Block, StopKind
from .path.interpolator import Waiting
from .plc_functions import PlcFunctions
from .state import Channel, DecoderFlag

_CHECK_PAUSED = DecoderFlag.WAIT_CONTINUE | DecoderFlag.WAIT_AFTER_ERROR


def channel_wait_reason(
    channel: Channel, path_reason: int, *, axes_missing: bool, internal_hold: bool,
) -> int:
    """The channel's reason: ERROR, HOLD (or a paused syntax check), suspended output,
    a start waiting for its axes, else ``path_reason`` (the run's own, NONE without a
    run). ``axes_missing``: the run (or the start) needs axes that are not linked;
    ``internal_hold``: a suspend request brakes the path."""
    state = channel.state
    if state not in WORKING_STATES:
        return WaitReason.ERROR if state == ChannelState.ERROR else WaitReason.NONE
    if state == ChannelState.HOLD:
        if channel.program.decoder_flags & _CHECK_PAUSED:
            return WaitReason.CHECK_PAUSE
        return WaitReason.FEED_HOLD
    if internal_hold or (axes_missing and channel.suspend.output_suspended):
        return WaitReason.OUTPUT_SUSPENDED
    if axes_missing:
        return WaitReason.AXIS_LINK
    return path_reason


def path_wait_reason(
    waiting: Waiting, waiting_at: Block | None, plc: PlcFunctions | None, *,
    has_motion: bool, override_per_mille: int, more_blocks: bool, manual_open: bool,
) -> WaitReason:
    """The reason of a run's path: what the interpolator waits for (``waiting`` at block
    ``waiting_at``; ``plc`` tells the spindle from the PLC, None when technology is
    suppressed), else override 0 while motion is buffered (``has_motion``), else an
    empty path that still expects blocks (``more_blocks``): the decoder, or, in
    extended MDI (``manual_open``), the operator's next manual block."""
    match waiting:
        case Waiting.NONE:
            if has_motion:
                return WaitReason.OVERRIDE_ZERO if override_per_mille == 0 else WaitReason.NONE
            if not more_blocks:
                return WaitReason.NONE
            return WaitReason.MANUAL_BLOCK if manual_open else WaitReason.DECODER
        case Waiting.DWELL:
            return WaitReason.DWELL
        case Waiting.SINGLE_BLOCK:
            return WaitReason.SINGLE_BLOCK
        case Waiting.PROGRAMMED_STOP:
            return _STOP_REASONS.get(
                waiting_at.stop if waiting_at is not None else StopKind.NONE, WaitReason.NONE)
        case Waiting.TECHNOLOGY:
            if plc is None:
                return WaitReason.NONE
            if plc.waits_for_spindle:
                return WaitReason.SPINDLE
            if plc.waits_for_plc:
                return WaitReason.PLC_ACKNOWLEDGE
            return WaitReason.NONE  # all acknowledged: the path goes on next cycle
    return WaitReason.NONE


# the programmed stop a path waits at; M2/M30 end the run (no reason)
_STOP_REASONS = {
    StopKind.PROGRAMMED: WaitReason.PROGRAMMED_STOP,
    StopKind.OPTIONAL: WaitReason.OPTIONAL_STOP,
    StopKind.MANUAL: WaitReason.MANUAL_MODE,
}


def manual_open(channel: Channel, keep_open: bool) -> bool:
    """Extended MDI: the run stays open for further manual blocks."""
    return keep_open and channel.mode == ChannelMode.MDI
