"""Objects of the operator's switches, the channel's machine state and the settings
that change behaviour (docs/kernel.md "Operator switches", docs/configuration.md
"Settings as objects").

Templates (``templates.ObjectTemplate``), one area of ``catalog.AREAS``. ISG's names,
offsets and units where ISG documents them:
``mc_command_block_ignore_w`` / ``_r`` and ``mc_active_block_ignore_r`` (COM 0x4/0x5/0x6,
TF5200 "Skipping of NC blocks", CNC objects); the channel axis's distance to go (COM
0x<a>0004, SGN32, 0.1 um: the offset TwinSharp reads). ``mc_command_M01_stop_enable_w``
/ ``_r`` carry TwinSharp's names (ISG's HLI control unit ``m01_stop_enable``) at
project offsets. Everything else is the project's (offsets 0x37xx, "project" in the
description), found by name through the COM object directory.
"""

from __future__ import annotations

from cnc_objects.protocol.constants import CncPort
from cnc_objects.protocol.datatypes import BOOLEAN, REAL64, SGN32, STRING, UNS16, UNS32
from cnc_objects.protocol.values import CoolantState, RapidOverrideMode

from .addressing import GroupBase
from .model import Access
from .templates import PLC_GROUP, CatalogSizes, ObjectTemplate, Scope

R, W, RW = Access.READ, Access.WRITE, Access.READ_WRITE
_CH, _AXIS, _PLATFORM, _HLI_CH = (Scope.CHANNEL, Scope.CHANNEL_AXIS, Scope.PLATFORM,
                                  Scope.PLC_CHANNEL)
COM, PLC = CncPort.COM, CncPort.PLC
COM_CH = GroupBase.COM_CHANNEL
PLC_ACKNOWLEDGES_CHARS = 256  # "M6 M8 M9 ...": the [plc] acknowledges list as text

OPERATOR_ROWS: tuple[ObjectTemplate, ...] = (
    # --- block skip (ISG: TF5200 skipping of NC blocks, CNC objects) ----------------------
    ObjectTemplate("mc_command_block_ignore_w", _CH, COM, COM_CH, 0x4, UNS32, W, "-",
              "Skip levels: bit n-1 skips the lines marked /n (/ alone = /1), 0x3FF all; "
              "0 runs every line. Read at the next program start"),
    ObjectTemplate("mc_command_block_ignore_r", _CH, COM, COM_CH, 0x5, UNS32, R, "-",
              "Skip levels commanded (mc_command_block_ignore_w)"),
    ObjectTemplate("mc_active_block_ignore_r", _CH, COM, COM_CH, 0x6, UNS32, R, "-",
              "Skip levels the running (or last) program was started with"),
    # the control unit gpCh[i].decoder_mc_control.program_block_ignore (ISG HLI,
    # MC_CONTROL_UNS32_UNIT; offsets in the PLC's area: project)
    ObjectTemplate("decoder_mc_control.program_block_ignore.command_w", _HLI_CH, PLC, PLC_GROUP,
              0x130, UNS32, RW, "-",
              "Skip levels the PLC commands (taken at program start while enable_w)"),
    ObjectTemplate("decoder_mc_control.program_block_ignore.enable_w", _HLI_CH, PLC, PLC_GROUP,
              0x134, BOOLEAN, RW, "-",
              "TRUE: a program start takes command_w; FALSE: the HMI's request (request_r)"),
    ObjectTemplate("decoder_mc_control.program_block_ignore.request_r", _HLI_CH, PLC, PLC_GROUP,
              0x138, UNS32, R, "-", "Skip levels the HMI requests (mc_command_block_ignore_w)"),
    ObjectTemplate("decoder_mc_control.program_block_ignore.state_r", _HLI_CH, PLC, PLC_GROUP,
              0x13C, UNS32, R, "-", "Skip levels in effect (mc_active_block_ignore_r)"),
    # --- optional stop (TwinSharp's names; ISG HLI m01_stop_enable) ------------------------
    ObjectTemplate("mc_command_M01_stop_enable_w", _CH, COM, COM_CH, 0x3700, BOOLEAN, W, "-",
              "TRUE: M1 stops like M0; FALSE: the path runs through M1. Read as a block "
              "enters the look-ahead buffer (TwinSharp name; project offset)"),
    ObjectTemplate("mc_command_M01_stop_enable_r", _CH, COM, COM_CH, 0x3701, BOOLEAN, R, "-",
              "The optional stop switch (TwinSharp name; project offset)"),
    # --- rapid override (P-CHAN-00181; OPC 40501 RapidOverride) ----------------------------
    ObjectTemplate("mc_command_rapid_override_w", _CH, COM, COM_CH, 0x3702, UNS16, W, "0.1 %",
              "Rapid override 0..1000 for G0 blocks, as g00_override_mode (P-CHAN-00181) "
              "says (project)"),
    ObjectTemplate("mc_command_rapid_override_r", _CH, COM, COM_CH, 0x3703, UNS16, R, "0.1 %",
              "Rapid override commanded (project)"),
    ObjectTemplate("mc_active_rapid_override_r", _CH, COM, COM_CH, 0x3704, UNS16, R, "0.1 %",
              "Override G0 blocks run with: the rapid override (ACTIVE), the smaller of "
              "feed and rapid override (MINIMUM_OF_G0_G1) or the feed override (NOT_USED) "
              "(project)"),
    ObjectTemplate("mc_g00_override_mode_r", _CH, COM, COM_CH, 0x3705, UNS16, R, "-",
              "P-CHAN-00181 g00_override_mode: 0 NOT_USED, 1 MINIMUM_OF_G0_G1, 2 ACTIVE, "
              "3 ACTIVE_EXTENDED (configuration; project)", RapidOverrideMode),
    # --- machine state an HMI shows (project) ---------------------------------------------
    ObjectTemplate("mc_coolant_state_r", _CH, COM, COM_CH, 0x3706, UNS16, R, "-",
              "Coolant: 0 OFF, 1 MIST (M7), 2 FLOOD (M8), 3 both; M9 and RESET switch it "
              "off; follows the output of the M function (project)", CoolantState),
    ObjectTemplate("mc_all_axes_referenced_r", _CH, COM, COM_CH, 0x3707, BOOLEAN, R, "-",
              "TRUE when every axis of the channel is homed (project)"),
    ObjectTemplate("mc_referencing_required_r", _CH, COM, COM_CH, 0x3708, BOOLEAN, R, "-",
              "TRUE while an axis of the channel that needs homing (P-AXIS-00277 "
              "prog_move_requires_homing) is not homed: a program may not move it (project)"),
    ObjectTemplate("distance_to_go_pcs", _AXIS, COM, COM_CH, 0x04, SGN32, R, "0.1 um",
              "Distance to go of the axis: end point of the block in the interpolator - "
              "command position; 0 without a block (offset as TwinSharp)"),
    # --- settings that change behaviour (configuration; project) -------------------------
    ObjectTemplate("cnc_programs_need_referenced_axes_r", _PLATFORM, COM, COM_CH, 0x1040, BOOLEAN,
              R, "-", "Configuration programs_need_referenced_axes: the default of every axis' "
              "P-AXIS-00277 prog_move_requires_homing (project)"),
    ObjectTemplate("cnc_tool_change_time_r", _PLATFORM, COM, COM_CH, 0x1041, REAL64, R, "s",
              "Configuration tool_change_time_s: the time M6 takes (project)"),
    ObjectTemplate("cnc_plc_acknowledges_r", _PLATFORM, COM, COM_CH, 0x1042,
              STRING(PLC_ACKNOWLEDGES_CHARS), R, "-",
              "Configuration [plc] acknowledges: the functions the PLC acknowledges over "
              "ADS, e.g. 'M6 M8 M9' (project)"),
    ObjectTemplate("mc_feed_override_max_r", _CH, COM, COM_CH, 0x3709, UNS16, R, "0.1 %",
              "Configuration feed_override_max: the largest feed override accepted "
              "(project)"),
    ObjectTemplate("mc_plc_auto_acknowledge_r", _CH, COM, COM_CH, 0x370A, BOOLEAN, R, "-",
              "Configuration techno.auto_acknowledge: the embedded PLC acknowledges M/H "
              "functions ([plc] acknowledges excepted) (project)"),
)


def operator_templates(sizes: CatalogSizes) -> tuple[ObjectTemplate, ...]:
    """The templates of operator switches, machine state and settings (one per row)."""
    return OPERATOR_ROWS
