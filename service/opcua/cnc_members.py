"""The members of the OPC 40502 (CNC Systems) instances and the objects they show, as
tables: channel, axis, spindle. Each entry is a ``Source``; a member the twin cannot
fill is ``fixed`` with the reason (docs/opcua.md lists them with the spec section).

Enumerations of the CNC nodeset (values as published): CncOperationMode Manual 0, MDA 1,
Automatic 2; CncChannelStatus Active 0, Interrupted 1, Reset 2; CncChannelProgramStatus
Stopped 0, Running 1, Waiting 2, Interrupted 3; CncAxisStatus InPosition 0, Moving 1,
Parked 2; CncSpindleStatus Stopped 0, InTargetArea 1, Accelerating 2, Decelerating 3;
CncSpindleTurnDirection None 0, CW 1, CCW 2.
"""

from __future__ import annotations

from asyncua import ua

from cnc_objects.protocol.values import ChannelMode, ChannelState

from .sources import Source, derived, fixed, plain, scaled
from .values import engineering_factor

_D, _U32, _I32 = ua.VariantType.Double, ua.VariantType.UInt32, ua.VariantType.Int32
_B, _S = ua.VariantType.Boolean, ua.VariantType.String

MM_PER_UM01 = engineering_factor("0.1 um")  # the objects' positions -> mm
POSITION_RANGE = (-(2**31) * MM_PER_UM01, (2**31 - 1) * MM_PER_UM01)  # mm: SGN32 in 0.1 um
OVERRIDE_RANGE = (0.0, 150.0)  # % (the feed override's and spindle override's limits)
FEED_RANGE = (0.0, 1e6)  # mm/min
SPEED_RANGE = (-1e5, 1e5)  # rpm, signed: negative turns CCW (M4)

#: the twin's channel mode -> CncOperationMode (STANDBY has none: Manual, no motion)
_OPERATION_MODE: dict[int, int] = {ChannelMode.STANDBY: 0, ChannelMode.MANUAL: 0, ChannelMode.MDI: 1,
                   ChannelMode.AUTOMATIC: 2}
_PROGRAM_STATUS: dict[int, int] = {ChannelState.ACTIVE: 1, ChannelState.HOLD: 3}
_SPINDLE_M = {1: 5, 2: 3, 4: 4, 8: 19}  # mc_spindle_mode_r bit -> M function
_COOLANT_M = {0: (9,), 1: (7,), 2: (8,), 3: (7, 8)}  # mc_coolant_state_r -> M functions


def _operation_mode(mode: int) -> int:
    return _OPERATION_MODE.get(mode, 0)


def _channel_status(state: int) -> int:
    """Active while a program or block runs, Interrupted in HOLD or ERROR, else Reset."""
    if state == ChannelState.ACTIVE:
        return 0
    if state in (ChannelState.HOLD, ChannelState.ERROR):
        return 1
    return 2


def _program_status(state: int, waiting: bool) -> int:
    if state == ChannelState.ACTIVE and waiting:
        return 2
    return _PROGRAM_STATUS.get(state, 0)


def _zero_offset_g(group: int) -> int:
    """The G function of a zero offset group: 0 G53, 1..6 G54..G59, 7.. G159."""
    return 53 + group if group <= 6 else 159


def _m_functions(spindle_mode: int, coolant: int) -> list[int]:
    return [_SPINDLE_M.get(spindle_mode, 5), *_COOLANT_M.get(coolant, (9,))]


#: CncDriveType's load, power and torque: the twin's drives are ideal, none is modelled;
#: 0 with a range of 0 (OPC 40502, CncDriveType).
DRIVE_UNMODELLED = {
    "ActLoad": fixed(0.0, _D, "the twin models no drive load (OPC 40502, CncDriveType)",
                     unit="%", limits=(0.0, 0.0)),
    "ActPower": fixed(0.0, _D, "the twin models no drive power (OPC 40502, CncDriveType)",
                      unit="W", limits=(0.0, 0.0)),
    "ActTorque": fixed(0.0, _D, "the twin models no drive torque (OPC 40502, CncDriveType)",
                       unit="N.m", limits=(0.0, 0.0)),
    "CmdTorque": fixed(0.0, _D, "the twin models no drive torque (OPC 40502, CncDriveType)",
                       unit="N.m", limits=(0.0, 0.0)),
}


def channel_members(c: int, has_axes: bool = True) -> dict[str, Source]:
    """CncChannelType's mandatory members (OPC 40502) for channel ``c``."""
    ch = f"ch{c}."
    jog = (scaled(ch + "ax1.manual_increment_w", "0.1 um", (0.0, 10.0)) if has_axes else
           fixed(0.0, _D, "the channel has no axis", unit="mm", limits=(0.0, 10.0)))
    return {
        "ActFeedrate": scaled(ch + "mc_active_feedrate_r", "um/s", FEED_RANGE),
        "CmdFeedrate": scaled(ch + "mc_command_feedrate_r", "um/s", FEED_RANGE),
        "ActOverride": scaled(ch + "mc_active_feed_override_r", "0.1 %", OVERRIDE_RANGE),
        "CmdOverride": scaled(ch + "mc_command_feed_override_r", "0.1 %", OVERRIDE_RANGE,
                              write_object=ch + "mc_command_feed_override_w"),
        "ActJogIncrement": jog,
        "ActMainProgramName": plain(ch + "mc_active_program_name_r", _S),
        "ActMainProgramFile": plain(ch + "mc_active_program_name_r", _S),
        "ActProgramName": plain(ch + "mc_active_file_name_r", _S),
        "ActProgramFile": plain(ch + "mc_active_file_name_r", _S),
        "ActProgramBlock": plain(ch + "actual_block_number", _S,
                                 lambda n: "" if n < 0 else f"N{n}"),
        "ActGFunctions": derived((ch + "mc_active_zero_offset_r",),
                                 lambda g: [_zero_offset_g(g)], _U32, array=True),
        "ActMFunctions": derived((ch + "mc_spindle_mode_r", ch + "mc_coolant_state_r"),
                                 _m_functions, _U32, array=True),
        "ActModalOffsetFunction": plain(ch + "mc_active_zero_offset_r", _U32, _zero_offset_g),
        "ActOperationMode": plain(ch + "mc_active_mode_r", _I32, _operation_mode),
        "CmdOperationMode": plain(ch + "mc_active_mode_r", _I32, _operation_mode),
        "ActProgramStatus": derived((ch + "mc_active_state_r", ch + "mc_waiting_for_start_r"),
                                    _program_status, _I32),
        "ActStatus": plain(ch + "mc_active_state_r", _I32, _channel_status),
        "BlockMode": plain(ch + "mc_active_single_block_r", _B, bool),
        "FeedHold": plain(ch + "mc_active_state_r", _B, lambda s: s == ChannelState.HOLD),
        "DryRunFeed": fixed(0.0, _D, "the twin has no dry-run feed (OPC 40502, "
                            "CncChannelType)", unit="mm/min", limits=FEED_RANGE),
        "ToolId": plain(ch + "mc_active_tool_r", _U32),
    }


def position(act: str, cmd: str, rem: str | None, unit: str = "0.1 um",
             shown_as: str | None = None) -> dict[str, Source]:
    """CncPositionVariableType's members (OPC 40502): ActPos, CmdPos, RemDist
    (``shown_as``: ``deg`` for a rotary axis, whose objects hold 0.0001 deg)."""
    members = {"ActPos": scaled(act, unit, shown_as=shown_as),
               "CmdPos": scaled(cmd, unit, shown_as=shown_as)}
    members["RemDist"] = (scaled(rem, unit, shown_as=shown_as) if rem is not None else
                          fixed(0.0, _D, "the twin keeps no remaining distance here",
                                unit=shown_as or "mm"))
    return members


def axis_members(axis: str, rotary: bool = False) -> dict[str, Source]:
    """CncAxisType's and CncDriveType's mandatory variables (OPC 40502) for the
    channel axis ``axis`` (``ch1.ax1.``)."""
    return {
        "ActStatus": plain(axis + "distance_to_go_pcs", _I32, lambda d: 0 if d == 0 else 1),
        "IsReferenced": plain(axis + "homing_referenced_r", _B, bool),
        "IsRotational": plain(axis + "axis_type", _B, lambda t: t == 2),
        "ZeroOffset": derived((axis + "command_position_acs", axis + "command_position_pcs"),
                              lambda acs, pcs: (acs - pcs) * MM_PER_UM01, _D,
                              unit="deg" if rotary else "mm", limits=POSITION_RANGE),
        "IsInactive": fixed(False, _B, "every configured axis is active"),
        "IsVirtual": fixed(True, _B, "the twin's drives are simulated (ideal drives)"),
        **DRIVE_UNMODELLED,
    }


def axis_positions(axis: str, rotary: bool = False) -> dict[str, dict[str, Source]]:
    """PosDirect (machine coordinates, ACS) and PosIndirect (workpiece coordinates) of
    ``axis``: the ideal drive follows its command, ActPos = CmdPos. A rotary axis's
    positions are in degrees."""
    deg = "deg" if rotary else None
    return {
        "PosDirect": position(axis + "command_position_acs", axis + "command_position_acs",
                              axis + "distance_to_go_pcs", shown_as=deg),
        "PosIndirect": position(axis + "actual_position_pcs", axis + "command_position_pcs",
                                axis + "distance_to_go_pcs", shown_as=deg),
    }


def _spindle_status(mode: int, reached: bool, rev: int) -> int:
    if rev == 0 and mode in (0, 1):
        return 0
    return 1 if reached else 2


def spindle_members(c: int) -> dict[str, Source]:
    """CncSpindleType's and CncDriveType's mandatory variables (OPC 40502) for the
    spindle of channel ``c``."""
    ch = f"ch{c}."
    return {
        "ActSpeed": scaled(ch + "mc_spindle_active_rev_r", "0.001 deg/s", SPEED_RANGE),
        "CmdSpeed": scaled(ch + "mc_spindle_cmd_rev_r", "0.001 deg/s", SPEED_RANGE),
        "ActOverride": scaled(ch + "mc_spindle_override_w", "0.1 %", OVERRIDE_RANGE),
        "CmdOverride": scaled(ch + "mc_spindle_override_w", "0.1 %", OVERRIDE_RANGE,
                              write_object=ch + "mc_spindle_override_w"),
        "ActStatus": derived((ch + "mc_spindle_mode_r", ch + "mc_spindle_speed_reached_r",
                              ch + "mc_spindle_active_rev_r"), _spindle_status, _I32),
        "ActTurnDirection": plain(ch + "mc_spindle_active_rev_r", _I32,
                                  lambda r: 0 if r == 0 else (1 if r > 0 else 2)),
        "ActGear": fixed(1, _U32, "the twin's spindle has one gear stage"),
        "CmdGear": fixed(1, _U32, "the twin's spindle has one gear stage"),
        "IsInactive": fixed(False, _B, "the spindle is always configured active"),
        "IsVirtual": fixed(True, _B, "the twin's drives are simulated (ideal drives)"),
        **DRIVE_UNMODELLED,
    }


def spindle_position(c: int) -> dict[str, Source]:
    """AnglePos of the spindle: its position after M19 (degrees)."""
    name = f"ch{c}.mc_spindle_position_r"
    return position(name, name, None, unit="deg")


def fixed_position(why: str) -> dict[str, Source]:
    """A position the channel has no axis for: 0 mm, ``why``."""
    return {name: fixed(0.0, _D, why, unit="mm") for name in ("ActPos", "CmdPos", "RemDist")}
