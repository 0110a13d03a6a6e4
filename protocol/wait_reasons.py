"""Why a channel does not move: the value set of ``ch<c>.mc_wait_reason_r`` (project).

ISG shows why the path stands still with status flags of the interpolator
(``StateBahn_Data``: ``X_WaitContinue``, ``X_WaitTechnoAcknowledge``,
``X_DwellTimeActive``, ``X_WaitErrorRemoval``, ...; docs/isg-notes.md section 9.3) and
with the channel state (HOLD). The project folds them into one enumeration per channel:
the reason an operator has to act on first (``WaitReason`` lists them by that
priority in docs/kernel.md). ``WAIT_REASON_TEXTS`` is the sentence a client shows for
each value; ``ch<c>.mc_wait_reason_text_r`` carries the same text.
"""

from __future__ import annotations

from enum import IntEnum


class WaitReason(IntEnum):
    """Why a working channel's path stands (or is about to stand); 0 = it does not."""

    NONE = 0  # not waiting: moving, or nothing to run (READY, ...)
    SINGLE_BLOCK = 1  # single block: stands at a block end until START (X_WaitContinue)
    PROGRAMMED_STOP = 2  # M0: stands until START (X_WaitContinue)
    OPTIONAL_STOP = 3  # M1: stands until START (X_WaitContinue)
    FEED_HOLD = 4  # feedhold (channel state HOLD) until START
    OVERRIDE_ZERO = 5  # feed (G0: rapid) override 0 %: the path has motion and stands
    PLC_ACKNOWLEDGE = 6  # an M/H/T function waits for the PLC (X_WaitTechnoAcknowledge)
    SPINDLE = 7  # M3/M4/M5/M19/S waits for the spindle: speed reached, stopped, oriented
    DWELL = 8  # G4 dwell time runs (X_DwellTimeActive)
    DECODER = 9  # the path has run out of blocks and waits for the decoder
    MANUAL_BLOCK = 10  # extended MDI (ADD_MDI_BLOCK): waits for the next manual block
    AXIS_LINK = 11  # the start waits until every axis of the channel is linked to its drive
    OUTPUT_SUSPENDED = 12  # suspend_axis_output: the axes are given up
    CHECK_PAUSE = 13  # the syntax check pauses (single step, after an error) until START
    ERROR = 14  # the channel is in ERROR and waits for RESET (X_WaitErrorRemoval)
    MANUAL_MODE = 15  # G200: manual mode in the program until START ("continue motion")


WAIT_REASON_TEXTS: dict[WaitReason, str] = {
    WaitReason.NONE: "",
    WaitReason.SINGLE_BLOCK: "single block: waiting for START after a block",
    WaitReason.PROGRAMMED_STOP: "M0 programmed stop: waiting for START",
    WaitReason.OPTIONAL_STOP: "M1 optional stop: waiting for START",
    WaitReason.FEED_HOLD: "feed hold: waiting for START",
    WaitReason.OVERRIDE_ZERO: "feed override (rapid override in G0) is 0 %",
    WaitReason.PLC_ACKNOWLEDGE: "waiting for the PLC to acknowledge an M/H/T function",
    WaitReason.SPINDLE: "waiting for the spindle (speed reached, stopped or oriented)",
    WaitReason.DWELL: "dwell time (G4) running",
    WaitReason.DECODER: "waiting for the decoder (no block to run)",
    WaitReason.MANUAL_BLOCK: "extended MDI: waiting for the next manual block",
    WaitReason.AXIS_LINK: "waiting until the channel's axes are linked to their drives",
    WaitReason.OUTPUT_SUSPENDED: "axis output suspended (suspend_axis_output)",
    WaitReason.CHECK_PAUSE: "syntax check paused: waiting for START",
    WaitReason.ERROR: "channel in ERROR: waiting for RESET",
    WaitReason.MANUAL_MODE: "G200 manual mode: jog the axes, then START",
}
WAIT_REASON_TEXT_CHARS = 84  # STRING(84): room for the longest text


def wait_reason_text(value: int) -> str:
    """The sentence for a value of ``mc_wait_reason_r`` (an unknown value is named as
    such, so a newer service's reason still reads sensibly)."""
    try:
        return WAIT_REASON_TEXTS[WaitReason(value)]
    except ValueError:
        return f"wait reason {value}"
