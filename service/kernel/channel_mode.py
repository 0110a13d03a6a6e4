"""The channel's operation mode and state (HLI ``channel_mc_control.mode_and_state``).

Modes and states carry the documented HLI values. Which event takes a channel from
which state to which is one table, ``channel_transitions.TRANSITIONS``, shown in
docs/kernel.md ("Channel mode and state"); in short:

* A mode is chosen only while the channel is not working (DESELECTED, SELECTED, READY);
  choosing a mode puts the channel in SELECTED (STANDBY: DESELECTED).
* AUTOMATIC: SELECTED --select program--> READY --START--> ACTIVE; the program's end
  returns to READY (the program stays selected and can be started again).
* MDI: a manual block is loaded and started at once (READY -> ACTIVE -> READY). With the
  execution mode bit ADD_MDI_BLOCK the end of a manual block is not the end of the
  program: the channel stays ACTIVE and further manual blocks continue the same program
  (same modal state, path distance and program time) until M30 or RESET.
* MANUAL (docs/manual.md): a jog, handwheel or homing motion takes SELECTED/READY to
  ACTIVE; when every manual motion is over the channel is READY. Feedhold brakes them
  (HOLD); START ends the hold.
* ACTIVE --feedhold--> HOLD --START--> ACTIVE.
* Any error -> ERROR; RESET from any state -> READY (AUTOMATIC with a program selected),
  DESELECTED (STANDBY) or SELECTED.
"""

from __future__ import annotations

# The value sets are part of the wire contract: defined in protocol, used here.
from cnc_objects.protocol.values import IDLE_STATES, ChannelMode, ChannelState

__all__ = ["IDLE_STATES", "SELECTABLE_MODES", "ChannelMode", "ChannelState", "describe"]


#: Modes a client may select with ``mc_command_mode_w``.
SELECTABLE_MODES = frozenset(
    {ChannelMode.STANDBY, ChannelMode.AUTOMATIC, ChannelMode.MDI, ChannelMode.MANUAL}
)


def describe(mode: int, state: int) -> str:
    """'AUTOMATIC/READY' for the values, tolerant of unknown numbers."""
    m = ChannelMode(mode).name if mode in ChannelMode._value2member_map_ else str(mode)
    s = ChannelState(state).name if state in ChannelState._value2member_map_ else str(state)
    return f"{m}/{s}"
