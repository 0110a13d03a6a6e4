"""Every state change of a channel, as one table (the idea of h11's ``_state.py``).

``TRANSITIONS[state][event]`` is where ``event`` takes a channel in ``state``; a pair that
is not in the table is not a transition of this kernel. ``ChannelRunner`` changes the
channel's state only through ``next_state``, which raises ``TransitionNotAllowed`` for a
pair outside the table: that is a kernel bug, never the answer to a client, because every
command checks ``allowed`` (or a stricter guard) first and answers a ``Refusal``.

Two targets depend on more than the state: they are named (``Target``) and resolved by
``resolve`` from the channel's mode and whether a program is selected. The table is the
documentation (docs/kernel.md shows it) and the oracle of tests/service/kernel/
test_channel_transitions.py.
"""

from __future__ import annotations

from enum import Enum, IntEnum

from .channel_mode import ChannelMode, ChannelState


class ChannelEvent(IntEnum):
    """What moves a channel from one state to another."""

    SELECT_MODE = 1  # a client chose the operation mode (mc_command_mode_w)
    SELECT_PROGRAM = 2  # a client selected a program of the store (selects AUTOMATIC too)
    START = 3  # START of the selected program, or a manual block: the run begins; in
    # MANUAL the first jog, handwheel or homing motion (manual_mode)
    RESUME = 4  # START in HOLD: the path (or the check's decoding) goes on
    HOLD = 5  # feedhold: decelerate on the path and stop
    CHECK_PAUSE = 6  # internal: the syntax check waits for START (error, single step, STOP)
    PROGRAM_END = 7  # internal: M30 or the end of the blocks (or of the check) was reached;
    # in MANUAL: every manual motion is over
    FAIL = 8  # internal: an error stopped the channel (or the channel cannot work)
    RESET = 9  # RESET: stop at once, clear the errors


class Target(Enum):
    """A target state that depends on the channel's mode and selected program (not an
    IntEnum: a named target must never compare equal to a state)."""

    MODE_SELECTED = "mode selected"  # STANDBY: DESELECTED; any other mode: SELECTED
    AFTER_RESET = "after reset"  # STANDBY: DESELECTED; AUTOMATIC with a program: READY;
    # any other: SELECTED


_IDLE, _SELECTED, _READY = ChannelState.DESELECTED, ChannelState.SELECTED, ChannelState.READY
_ACTIVE, _HOLD, _ERROR = ChannelState.ACTIVE, ChannelState.HOLD, ChannelState.ERROR
E = ChannelEvent

#: The channel's transitions: state -> event -> target state (or named target).
TRANSITIONS: dict[ChannelState, dict[ChannelEvent, ChannelState | Target]] = {
    ChannelState.DESELECTED: {
        E.SELECT_MODE: Target.MODE_SELECTED,
        E.SELECT_PROGRAM: _READY,
        E.START: _ACTIVE,  # a manual block selects MDI and starts
        E.FAIL: _ERROR,  # a start-up message, a jog-of-path channel at init
        E.RESET: Target.AFTER_RESET,
    },
    ChannelState.SELECTED: {
        E.SELECT_MODE: Target.MODE_SELECTED,
        E.SELECT_PROGRAM: _READY,
        E.START: _ACTIVE,  # a manual block
        E.FAIL: _ERROR,
        E.RESET: Target.AFTER_RESET,
    },
    ChannelState.READY: {
        E.SELECT_MODE: Target.MODE_SELECTED,
        E.SELECT_PROGRAM: _READY,
        E.START: _ACTIVE,  # START in AUTOMATIC, or a manual block
        E.FAIL: _ERROR,
        E.RESET: Target.AFTER_RESET,
    },
    ChannelState.ACTIVE: {
        E.HOLD: _HOLD,
        E.CHECK_PAUSE: _HOLD,
        E.PROGRAM_END: _READY,
        E.FAIL: _ERROR,
        E.RESET: Target.AFTER_RESET,
    },
    ChannelState.HOLD: {
        E.RESUME: _ACTIVE,
        E.CHECK_PAUSE: _HOLD,  # the check still waits
        E.PROGRAM_END: _READY,  # the path reached the end while braking, or the check ended
        E.FAIL: _ERROR,
        E.RESET: Target.AFTER_RESET,
    },
    ChannelState.ERROR: {
        E.FAIL: _ERROR,  # a further error (start-up messages, then the jog-of-path check)
        E.RESET: Target.AFTER_RESET,
    },
}

del E


class TransitionNotAllowed(Exception):
    """The kernel tried a state change that is not in ``TRANSITIONS`` (a kernel bug)."""

    def __init__(self, state: int, event: ChannelEvent) -> None:
        super().__init__(
            f"{event.name} is not a transition of a channel in state "
            f"{ChannelState(state).name} (channel_transitions.TRANSITIONS)"
        )
        self.state = state
        self.event = event


def allowed(state: int, event: ChannelEvent) -> bool:
    """True when ``event`` is a transition of a channel in ``state``."""
    return event in TRANSITIONS.get(ChannelState(state), {})


def resolve(target: ChannelState | Target, mode: int, program_selected: bool) -> ChannelState:
    """The state a (named) target means for a channel in ``mode``."""
    if not isinstance(target, Target):
        return target
    if mode == ChannelMode.STANDBY:
        return _IDLE
    if target is Target.AFTER_RESET and mode == ChannelMode.AUTOMATIC and program_selected:
        return _READY
    return _SELECTED


def next_state(state: int, event: ChannelEvent, mode: int, program_selected: bool) -> ChannelState:
    """Where ``event`` takes a channel in ``state`` and ``mode``; raises
    ``TransitionNotAllowed`` when the table has no such transition."""
    target = TRANSITIONS.get(ChannelState(state), {}).get(event)
    if target is None:
        raise TransitionNotAllowed(state, event)
    return resolve(target, mode, program_selected)


def render_table() -> str:
    """``TRANSITIONS`` as a Markdown table (docs/kernel.md shows it; a test compares)."""
    events = list(ChannelEvent)
    lines = ["| state \\ event | " + " | ".join(e.name for e in events) + " |",
             "|---" * (len(events) + 1) + "|"]
    for state, row in TRANSITIONS.items():
        cells = []
        for event in events:
            target = row.get(event)
            if target is None:
                cells.append("-")
            elif isinstance(target, Target):
                cells.append(f"*{target.value}*")
            else:
                cells.append(target.name)
        lines.append(f"| {state.name} | " + " | ".join(cells) + " |")
    return "\n".join(lines)
