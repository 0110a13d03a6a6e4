"""What the numbers of the enumeration objects mean: the documented value sets.

An object such as ``ch1.mc_active_state_r`` carries a plain UNS32 on the wire; its
meaning (3 = READY) is part of the contract between the service and every client, like
an ADS state. The sets are defined once here: the kernel works with them, the catalog
names them in browse replies (``ObjectInfo.enum`` on the client side), and clients may
use them directly.

Execution mode is a bit set, not an enumeration: its objects carry no value names (a
value such as 0x48 is a combination); ``ExecutionMode`` names the single bits.
"""

from __future__ import annotations

from enum import IntEnum, IntFlag


class ChannelMode(IntEnum):
    """Operation mode of a channel (HLI ``mode_and_state`` values)."""

    STANDBY = 1  # no operation mode selected
    AUTOMATIC = 2  # programs from the program store
    MDI = 3  # manual data input: manual blocks
    MANUAL = 4  # jog / handwheel (manual mode; no NC program)
    REFERENCE = 5  # homing (not offered by this kernel's commands)


class ChannelState(IntEnum):
    """State of the channel within its mode (HLI ``mode_and_state`` values)."""

    DESELECTED = 1  # the mode is not selected
    SELECTED = 2  # the mode is selected, nothing to run yet
    READY = 3  # a program (or manual block) is ready to start
    ACTIVE = 4  # running
    HOLD = 5  # feedhold: the path is stopped and resumes on START
    ERROR = 6  # an error stopped the channel; RESET clears it


WORKING_STATES: frozenset[ChannelState] = frozenset({ChannelState.ACTIVE, ChannelState.HOLD})
"""The channel is working its program or manual block: running, or stopped in a feedhold
that START resumes. READY, SELECTED, ERROR and DESELECTED are not."""

ERRORS_LISTED = 8
"""Errors a channel lists (``ch<c>.mc_error_<k>_*_r``, k = 1..8): the first of a run, whose
first entry is the cause."""
MESSAGES_LISTED = 8
"""``#MSG`` texts a channel shows (``ch<c>.mc_message_<k>_text_r``, k = 1..8, 1 = newest)."""

IDLE_STATES: frozenset[ChannelState] = frozenset(
    {ChannelState.DESELECTED, ChannelState.SELECTED, ChannelState.READY})
"""The channel has nothing in hand: a mode may be selected, a program started."""


class LinkState(IntEnum):
    """State of a logical axis's link to its physical axis (FCT-C15 ``link_state``)."""

    LINKED = 0  # the link exists: this logical axis drives the physical axis
    REQUESTED = 1  # the physical axis is requested from the position controller
    WAITING_ACK = 2  # waiting for the position controller's acknowledgement


class ContourBlockType(IntEnum):
    """``block_type`` of a contour look-ahead reply entry (FCT-C40)."""

    NONE = 0  # no entry: ends the list
    LINEAR = 1  # straight line
    CIRCULAR = 2  # circular arc
    LOG_ON = 3  # #CONTOUR LOOKAHEAD LOG ON: start of the marked area
    LOG_PARAM = 4  # #CONTOUR LOOKAHEAD LOG [PARAM=..] inside the area
    LOG_OFF = 5  # #CONTOUR LOOKAHEAD LOG OFF: end of the marked area
    POLYNOMIAL = 6  # polynomial contour element


AXIS_TYPE_CODES: dict[str, int] = {"linear": 1, "rotary": 2}
"""ISG's codes of kenngr.achs_typ (ACHSTYP_TRANSLATOR, ACHSTYP_ROTATOR): the machine
configuration's ``axis_type`` and the object ``ch<c>.ax<a>.axis_type``."""
ROTARY_AXIS_CODE = AXIS_TYPE_CODES["rotary"]


class ExecutionMode(IntFlag):
    """Execution mode bits of a channel (``mc_command_execution_mode_w``); a value is
    their OR."""

    ISG_STANDARD = 0x0  # normal machining
    BLOCK_SEARCH = 0x1  # SV: block search
    SOLLKON = 0x2  # contour visualisation with output
    ON_LINE = 0x4  # online
    SYNCHK = 0x8  # syntax check
    PROD_TIME = 0x10  # production time calculation
    ONLINE_PROD_TIME = 0x20  # online production time calculation
    MACHINE_LOCK = 0x40  # dry run: no axis motion
    ADD_MDI_BLOCK = 0x80  # additional MDI block
    KIN_TRAFO_OFF = 0x100  # kinematic transformation off
    SOLLKON_NO_OUTPUT = 0x800  # with SOLLKON: contour visualisation without output
    BEARB_MODE_SCENE = 0x1000  # machining scene mode
    SUPPRESS_TECHNO_OUTPUT = 0x2000  # no M/H/T output


class ManualOperationMode(IntEnum):
    """Operation mode of an axis in manual mode (HLI
    ``bahn_state.coord_r[i].hb_display_r.operation_mode``)."""

    NONE = 0  # no operation mode selected
    HANDWHEEL = 1  # the axis follows the handwheel counter
    CONTINUOUS = 2  # continuous jog: moves while the jog key is held
    INCREMENTAL = 3  # jog mode: one increment per key press


class SpindleM(IntEnum):
    """The spindle M functions (ISG: a spindle takes one of them per block, error 20155)."""

    CW = 3  # M3
    CCW = 4  # M4
    STOP = 5  # M5
    ORIENT = 19  # M19


SPINDLE_M_FUNCTIONS = frozenset(int(m) for m in SpindleM)


class SpindleMode(IntEnum):
    """Mode of the spindle (HLI ``gpAx[..]^.ipo_state.spindle.mode_r``; the object
    ``ch<c>.mc_spindle_mode_r``)."""

    M05 = 1  # stopped
    M03 = 2  # turning clockwise
    M04 = 4  # turning counter-clockwise
    M19 = 8  # positioning (orientation)
    PLCOPEN = 16  # moved by a PLCopen function block (not offered by this kernel)
    RPF = 32  # reference point run (not offered by this kernel)


class CoolantState(IntEnum):
    """Coolant as the program commanded it (``ch<c>.mc_coolant_state_r``; project: ISG
    leaves M7/M8/M9 to the PLC)."""

    OFF = 0  # M9, RESET, start-up
    MIST = 1  # M7
    FLOOD = 2  # M8
    MIST_AND_FLOOD = 3  # M7 and M8


class RapidOverrideMode(IntEnum):
    """How the rapid override acts (P-CHAN-00181 ``g00_override_mode``)."""

    NOT_USED = 0  # the feed override acts on G0 and feed blocks
    MINIMUM_OF_G0_G1 = 1  # G0: the smaller of feed and rapid override
    ACTIVE = 2  # G0: the rapid override only; feed blocks: the feed override
    ACTIVE_EXTENDED = 3  # as ACTIVE (also homing and manual mode on ISG's kernel)


def value_names(values: type[IntEnum]) -> dict[int, str]:
    """``{3: "READY", ...}``: the names of an enumeration's values."""
    return {int(member): member.name for member in values}
