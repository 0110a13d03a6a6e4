"""The catalog: every CNC object the kernel offers, declared once.

Each ``ObjectTemplate`` is one row of the ISG object tables (reference/cnc-objects.md);
the rows are grouped in areas (``AREAS``: this module's own and one module each for
technology, manual mode, operator switches, tools, alarms), each a function of the
machine's table sizes; ``build_objects`` expands them over a machine layout. The
service binds each instance to kernel state by its ``element`` name; this module holds
no kernel logic.

Objects whose offsets the public ISG documentation does not give (platform statistics,
feed override names) are marked "project" in their description; their addresses are
stable and found by name through the COM object directory, as ISG tools do.
"""

from __future__ import annotations

from collections.abc import Callable
from enum import IntEnum

from cnc_objects.protocol.constants import CncPort
from cnc_objects.protocol.datatypes import BOOLEAN, REAL64, SGN32, STRING, UNS16, UNS32, DataType
from cnc_objects.protocol.values import (
    ERRORS_LISTED,
    MESSAGES_LISTED,
    ChannelMode,
    ChannelState,
    ContourBlockType,
    LinkState,
)
from cnc_objects.protocol.wait_reasons import WAIT_REASON_TEXT_CHARS, WaitReason

from .addressing import GroupBase
from .catalog_alarms import alarm_templates
from .catalog_manual import manual_templates
from .catalog_operator import operator_templates
from .catalog_technology import technology_templates
from .catalog_tools import tool_templates
from .model import Access, CncObject
from .templates import PLC_GROUP as PLC_GROUP
from .templates import CatalogSizes as CatalogSizes
from .templates import ChannelLayout as ChannelLayout
from .templates import MachineLayout as MachineLayout
from .templates import ObjectTemplate as ObjectTemplate
from .templates import Scope as Scope
from .templates import instances

# gpCh[i].contour_lookahead.response.block[0..N-1] (HLI_CONTOUR_LOOKAHEAD_BLOCK)
CONTOUR_RESPONSE_BLOCKS = 32
CONTOUR_RESPONSE_OFFSET, CONTOUR_BLOCK_STRIDE = 0x300, 0x50
CONTOUR_BLOCK_FIELDS: tuple[tuple[str, int, DataType, str, str], ...] = (
    ("block_type", 0x00, UNS16, "-",
     "0 none (ends the list), 1 linear, 2 circular, 3 LOG ON, 4 LOG PARAM, 5 LOG OFF, "
     "6 polynomial"),
    ("block_number", 0x04, SGN32, "-", "programmed N; -1 = none"),
    ("block_count_r", 0x08, UNS32, "-", "number of the block in the run (mc_block_count_r)"),
    ("start_position", 0x10, REAL64, "0.1 um", "sum of the lengths of all earlier elements"),
    ("length", 0x18, REAL64, "0.1 um", "element length; PARAM value for types 3..5"),
    ("programmed_radius", 0x20, REAL64, "0.1 um", "radius of the programmed arc"),
    ("compensated_radius", 0x28, REAL64, "0.1 um", "radius on the compensated path"),
    ("circle_angle", 0x30, REAL64, "rad", "swept angle: cw in [-2pi, 0), ccw in (0, 2pi]"),
    ("length_min", 0x38, REAL64, "0.1 um", "length on the scaled contour (die sinking): 0"),
    ("tangent_variation", 0x40, REAL64, "rad", "angle to the previous motion element"),
)
#: The enumeration fields of a contour reply entry and their value sets.
CONTOUR_BLOCK_VALUES: dict[str, type[IntEnum]] = {"block_type": ContourBlockType}


R, W, RW = Access.READ, Access.WRITE, Access.READ_WRITE
GEO, COM, PLC = CncPort.GEO, CncPort.COM, CncPort.PLC
IPO = GroupBase.GEO_INTERPOLATOR
COM_CH = GroupBase.COM_CHANNEL
COM_AX = GroupBase.COM_PLATFORM_AXIS

# ch<c>.<name>_r of the #TRAFO/#HSC/#SLOPE/#FILTER/G133/G134 settings (nc.technology):
# (name, MachiningSettings field, type, unit, meaning), at COM 0x3210 + n
MACHINING_FIELDS: tuple[tuple[str, str, DataType, str, str], ...] = (
    ("trafo_active", "trafo", BOOLEAN, "-", "#TRAFO ON: kinematic transformation selected"),
    ("hsc_active", "hsc", BOOLEAN, "-", "#HSC ON: high-speed cutting mode selected"),
    ("hsc_surface", "hsc_surface", BOOLEAN, "-", "#HSC ON [SURFACE]"),
    ("hsc_path_dev", "hsc_path_dev_mm", REAL64, "mm", "#HSC ON [PATH_DEV=..]; 0 = not set"),
    ("hsc_track_dev", "hsc_track_dev_mm", REAL64, "mm", "#HSC ON [TRACK_DEV=..]; 0 = not set"),
    ("slope_type", "slope", STRING(16), "-", "#SLOPE [TYPE=..]: STEP, TRAPEZ or HSC"),
    ("filter_active", "filter", BOOLEAN, "-", "#FILTER ON: axis filter selected"),
    ("filter_ax_dev", "filter_ax_dev_mm", REAL64, "mm", "#FILTER ON [AX_DEV=..]; 0 = not set"),
    ("acc_weight", "acc_weight_pct", REAL64, "%", "G133 = ..: acceleration weighting"),
    ("ramp_weight", "ramp_weight_pct", REAL64, "%", "G134 = ..: ramp time weighting"),
)

CORE_TEMPLATES: tuple[ObjectTemplate, ...] = (
    # --- GEO interpolator, channel axes (FCT-C15 "CNC objects") -------------------------
    ObjectTemplate(
        "requested_link_to_physical_axis", Scope.CHANNEL_AXIS, GEO, IPO, 0x16, UNS16, R, "-",
        "Physical axis this logical axis requests (channel switchover)",
    ),
    ObjectTemplate(
        "actual_link_to_physical_axis", Scope.CHANNEL_AXIS, GEO, IPO, 0x17, UNS16, R, "-",
        "Physical axis currently linked to this logical axis; 0 = none",
    ),
    ObjectTemplate(
        "link_state", Scope.CHANNEL_AXIS, GEO, IPO, 0x18, UNS32, R, "-",
        "Axis request state: 0 link exists, 1 physical axis requested, "
        "2 waiting for acknowledgement", LinkState,
    ),
    ObjectTemplate(
        "command_position_acs", Scope.CHANNEL_AXIS, GEO, IPO, 0x02, SGN32, R, "0.1 um",
        "Command position of the channel axis (interpolator output) (project offset)",
    ),
    ObjectTemplate(
        "position_offset", Scope.CHANNEL_AXIS, GEO, IPO, 0x800, SGN32, R, "0.1 um",
        "Command position of the channel axis - position of its physical axis "
        "(jog of path, FCT-C15) (project offset)",
    ),
    ObjectTemplate(
        "vel_max", Scope.CHANNEL_AXIS, GEO, IPO, 0x801, REAL64, R, "mm/s",
        "Maximum axis velocity the planner uses (getriebe[0].dynamik.vb_max) (project offset)",
    ),
    ObjectTemplate(
        "acc_max", Scope.CHANNEL_AXIS, GEO, IPO, 0x802, REAL64, R, "mm/s^2",
        "Maximum axis acceleration the planner uses (getriebe[0].dynamik.a_max) "
        "(project offset)",
    ),
    ObjectTemplate(
        "vel_jump_max", Scope.CHANNEL_AXIS, GEO, IPO, 0x803, REAL64, R, "mm/s",
        "Permitted velocity jump of the axis at a block transition (project offset)",
    ),
    # --- GEO interpolator, channel -------------------------------------------------------
    ObjectTemplate(
        "dist_prog_start", Scope.CHANNEL, GEO, IPO, 0x56, REAL64, R, "0.1 um",
        "Path distance from program start on the compensated path",
    ),
    ObjectTemplate(
        "lookahead_blocks", Scope.CHANNEL, GEO, IPO, 0x801, UNS32, R, "-",
        "Blocks the look-ahead buffer holds (P-CHAN-00650/00653), the size the planner "
        "uses (project offset)",
    ),
    ObjectTemplate(
        "remaining_path_in_block", Scope.CHANNEL, GEO, IPO, 0x08, REAL64, R, "0.1 um",
        "Remaining path of the block in the interpolator (offset as TwinSharp)",
    ),
    ObjectTemplate(
        "actual_path_velocity", Scope.CHANNEL, GEO, IPO, 0x15, REAL64, R, "um/s",
        "Actual path velocity, feed override applied (offset as TwinSharp)",
    ),
    ObjectTemplate(
        "programmed_path_velocity", Scope.CHANNEL, GEO, IPO, 0x16, REAL64, R, "um/s",
        "Programmed path velocity F of the block in the interpolator (offset as TwinSharp)",
    ),
    ObjectTemplate(
        "actual_block_number", Scope.CHANNEL, GEO, IPO, 0x21, SGN32, R, "-",
        "N number of the block in the interpolator; -1 = the block has none "
        "(offset as TwinSharp)",
    ),
    ObjectTemplate(
        "actual_block_count", Scope.CHANNEL, GEO, IPO, 0x2E, SGN32, R, "-",
        "Blocks finished since program start (offset as TwinSharp)",
    ),
    # --- COM channel ----------------------------------------------------------------------
    ObjectTemplate(
        "mc_command_feed_override_w", Scope.CHANNEL, COM, COM_CH, 0x09, UNS16, W, "0.1 %",
        "Commanded feed override (project name; offset as TwinSharp)",
    ),
    ObjectTemplate(
        "mc_command_feed_override_r", Scope.CHANNEL, COM, COM_CH, 0x0A, UNS16, R, "0.1 %",
        "Commanded feed override, read back",
    ),
    ObjectTemplate(
        "mc_active_feed_override_r", Scope.CHANNEL, COM, COM_CH, 0x0C, UNS16, R, "0.1 %",
        "Feed override in effect in the interpolator",
    ),
    ObjectTemplate(
        "mc_command_execution_mode_w", Scope.CHANNEL, COM, COM_CH, 0x3F, SGN32, W, "-",
        "Command the channel's execution mode (bit mask; takes effect at program start)",
    ),
    ObjectTemplate(
        "mc_command_execution_mode_r", Scope.CHANNEL, COM, COM_CH, 0x40, SGN32, R, "-",
        "Commanded execution mode",
    ),
    ObjectTemplate(
        "mc_active_execution_mode_r", Scope.CHANNEL, COM, COM_CH, 0x41, SGN32, R, "-",
        "Execution mode in effect",
    ),
    ObjectTemplate(
        "mc_command_single_block_w", Scope.CHANNEL, COM, COM_CH, 0x01, BOOLEAN, W, "-",
        "Single block on (TRUE) or off (offset as TwinSharp)",
    ),
    ObjectTemplate(
        "mc_active_single_block_r", Scope.CHANNEL, COM, COM_CH, 0x03, BOOLEAN, R, "-",
        "Single block mode active (offset as TwinSharp)",
    ),
    # --- COM channel control (project offsets; HLI mode_and_state values) ----------------
    ObjectTemplate(
        "mc_active_mode_r", Scope.CHANNEL, COM, COM_CH, 0x3001, UNS32, R, "-",
        "Operation mode: 1 STANDBY, 2 AUTOMATIC, 3 MDI, 4 MANUAL (project)", ChannelMode,
    ),
    ObjectTemplate(
        "mc_active_state_r", Scope.CHANNEL, COM, COM_CH, 0x3002, UNS32, R, "-",
        "State: 1 DESELECTED, 2 SELECTED, 3 READY, 4 ACTIVE, 5 HOLD, 6 ERROR (project)",
        ChannelState,
    ),
    ObjectTemplate(
        "mc_command_mode_w", Scope.CHANNEL, COM, COM_CH, 0x3003, UNS32, W, "-",
        "Select the operation mode (1..4); only while the channel is not working (project)",
        ChannelMode,
    ),
    ObjectTemplate(
        "mc_command_program_name_w", Scope.CHANNEL, COM, COM_CH, 0x3004, STRING(84), W, "-",
        "Select a program of the program store: AUTOMATIC/READY (project)",
    ),
    ObjectTemplate(
        "mc_active_program_name_r", Scope.CHANNEL, COM, COM_CH, 0x3005, STRING(84), R, "-",
        "Selected program (project)",
    ),
    ObjectTemplate(
        "mc_command_start_w", Scope.CHANNEL, COM, COM_CH, 0x3006, BOOLEAN, W, "-",
        "Write TRUE: start the selected program, resume from HOLD, continue after M0/M1 "
        "or a single-block stop (project)",
    ),
    ObjectTemplate(
        "mc_command_hold_w", Scope.CHANNEL, COM, COM_CH, 0x3007, BOOLEAN, W, "-",
        "Write TRUE: feedhold, decelerate on the path and stop (project)",
    ),
    ObjectTemplate(
        "mc_command_reset_w", Scope.CHANNEL, COM, COM_CH, 0x3008, BOOLEAN, W, "-",
        "Write TRUE: RESET the channel from any state (project)",
    ),
    ObjectTemplate(
        "mc_command_manual_block_w", Scope.CHANNEL, COM, COM_CH, 0x3009, STRING(992), W, "-",
        "Run NC blocks (lines separated by LF or CR LF) as manual blocks, MDI (project)",
    ),
    ObjectTemplate(
        "mc_active_file_name_r", Scope.CHANNEL, COM, COM_CH, 0x300A, STRING(84), R, "-",
        "File of the block in the interpolator (FCT-C9 name; project offset)",
    ),
    ObjectTemplate(
        "mc_active_file_offset_r", Scope.CHANNEL, COM, COM_CH, 0x300B, UNS32, R, "byte",
        "Byte offset of that block's line in its file (FCT-C9 name; project offset)",
    ),
    ObjectTemplate(
        "mc_active_line_r", Scope.CHANNEL, COM, COM_CH, 0x300C, UNS32, R, "-",
        "Line of that block in its file, from 1; 0 = none (project)",
    ),
    ObjectTemplate(
        "mc_block_count_r", Scope.CHANNEL, COM, COM_CH, 0x300D, UNS32, R, "-",
        "Blocks finished since program start (TwinSharp name; project offset)",
    ),
    ObjectTemplate(
        "mc_command_feedrate_r", Scope.CHANNEL, COM, COM_CH, 0x300E, REAL64, R, "um/s",
        "Programmed feed F of the block in the interpolator (TwinSharp name; project offset)",
    ),
    ObjectTemplate(
        "mc_active_feedrate_r", Scope.CHANNEL, COM, COM_CH, 0x300F, REAL64, R, "um/s",
        "Actual path feed, override applied (TwinSharp name; project offset)",
    ),
    ObjectTemplate(
        "program_time", Scope.CHANNEL, COM, COM_CH, 0x3010, REAL64, R, "s",
        "Kernel time since the program started; frozen at its end (project)",
    ),
    ObjectTemplate(
        "mc_waiting_for_start_r", Scope.CHANNEL, COM, COM_CH, 0x3011, BOOLEAN, R, "-",
        "TRUE while the path stands at M0/M1 or a single-block stop and waits for START "
        "(project)",
    ),
    ObjectTemplate(
        "mc_manual_blocks_done_r", Scope.CHANNEL, COM, COM_CH, 0x3012, UNS32, R, "-",
        "Manual blocks (MDI writes) finished since the service started (project)",
    ),
    # --- COM channel wait reason (project offsets 0x36xx; docs/kernel.md "Wait reasons")
    ObjectTemplate(
        "mc_wait_reason_r", Scope.CHANNEL, COM, COM_CH, 0x3600, UNS32, R, "-",
        "Why the channel stands: 0 NONE, 1 SINGLE_BLOCK, 2 PROGRAMMED_STOP (M0), "
        "3 OPTIONAL_STOP (M1), 4 FEED_HOLD, 5 OVERRIDE_ZERO, 6 PLC_ACKNOWLEDGE, 7 SPINDLE, "
        "8 DWELL, 9 DECODER, 10 MANUAL_BLOCK, 11 AXIS_LINK, 12 OUTPUT_SUSPENDED, "
        "13 CHECK_PAUSE, 14 ERROR, 15 MANUAL_MODE (G200) (project, after ISG's StateBahn wait "
        "flags)", WaitReason,
    ),
    ObjectTemplate(
        "mc_wait_reason_text_r", Scope.CHANNEL, COM, COM_CH, 0x3601,
        STRING(WAIT_REASON_TEXT_CHARS), R, "-",
        "Why the channel stands, as a sentence; empty when it does not (project)",
    ),
    ObjectTemplate(
        "mc_error_count_r", Scope.CHANNEL, COM, COM_CH, 0x3020, UNS32, R, "-",
        "Errors raised since program start or RESET; the first 8 are in mc_error_<k>_* "
        "(project)",
    ),
    *(
        ObjectTemplate(
            f"mc_error_{k}_{field}_r", Scope.CHANNEL, COM, COM_CH, 0x3020 + 0x10 * k + n,
            dtype, R, "-", f"Error {k} of the list: {meaning} (project)",
        )
        for k in range(1, ERRORS_LISTED + 1)
        for n, (field, dtype, meaning) in enumerate((
            ("id", UNS32, "ISG-style error id; 0 = no error"),
            ("text", STRING(256), "message"),
            ("file", STRING(84), "NC file"),
            ("line", UNS32, "line in the file, from 1"),
            ("column", UNS32, "column in the line, from 1"),
            ("warning", BOOLEAN, "TRUE for a warning (the channel was not stopped)"),
        ))
    ),
    # --- COM channel axes (offsets as TwinSharp, IG 0x12010<c>, IO 0x<a>00xx) -------------
    ObjectTemplate(
        "logical_axis_number", Scope.CHANNEL_AXIS, COM, COM_CH, 0x01, UNS16, R, "-",
        "Logical axis number (kopf.achs_nr) of the channel axis",
    ),
    ObjectTemplate(
        "axis_name", Scope.CHANNEL_AXIS, COM, COM_CH, 0x02, STRING(16), R, "-",
        "Name of the channel axis",
    ),
    ObjectTemplate(
        "axis_type", Scope.CHANNEL_AXIS, COM, COM_CH, 0x03, UNS16, R, "-",
        "kenngr.achs_typ (P-AXIS-00018): 1 translatory (positions 0.1 um), 2 rotary "
        "(positions 0.0001 degree)",
    ),
    # --- COM platform (project offsets; found by name through the directory) -------------
    ObjectTemplate(
        "cnc_version_r", Scope.PLATFORM, COM, COM_CH, 0x1001, STRING(32), R, "-",
        "Kernel version (project)",
    ),
    ObjectTemplate(
        "cnc_number_of_channel_r", Scope.PLATFORM, COM, COM_CH, 0x1002, UNS16, R, "-",
        "Number of configured channels (project)",
    ),
    ObjectTemplate(
        "cnc_number_of_axis_r", Scope.PLATFORM, COM, COM_CH, 0x1003, UNS32, R, "-",
        "Number of configured physical axes (project)",
    ),
    ObjectTemplate(
        "cnc_cycle_time_r", Scope.PLATFORM, COM, COM_CH, 0x1010, UNS32, R, "us",
        "Cycle time of the GEO task (project)",
    ),
    ObjectTemplate(
        "cnc_tick_counter_r", Scope.PLATFORM, COM, COM_CH, 0x1011, UNS32, R, "-",
        "Cycles run by the GEO task since start, modulo 2**32 (project)",
    ),
    ObjectTemplate(
        "cnc_cycle_overruns_r", Scope.PLATFORM, COM, COM_CH, 0x1012, UNS32, R, "-",
        "Cycles that started later than one cycle after their deadline (project)",
    ),
    ObjectTemplate(
        "cnc_cycle_jitter_max_r", Scope.PLATFORM, COM, COM_CH, 0x1013, UNS32, R, "us",
        "Largest lateness of a cycle start against its deadline (project)",
    ),
    ObjectTemplate(
        "cnc_cycle_exec_time_max_r", Scope.PLATFORM, COM, COM_CH, 0x1014, UNS32, R, "us",
        "Longest execution time of one cycle (project)",
    ),
    ObjectTemplate(
        "cnc_kernel_time_r", Scope.PLATFORM, COM, COM_CH, 0x1015, REAL64, R, "s",
        "Kernel time: cycles run times the cycle time (virtual or real) (project)",
    ),
    ObjectTemplate(
        "cnc_kernel_running_r", Scope.PLATFORM, COM, COM_CH, 0x1016, BOOLEAN, R, "-",
        "TRUE while the cycle task runs (ADS state RUN), FALSE after STOP (project)",
    ),
    ObjectTemplate(
        "cnc_notifications_r", Scope.PLATFORM, COM, COM_CH, 0x1017, UNS32, R, "-",
        "Device notifications open, of all clients of both front ends; a client that is "
        "gone is no longer counted (project)",
    ),
    ObjectTemplate(
        "cnc_notification_clients_r", Scope.PLATFORM, COM, COM_CH, 0x1018, UNS32, R, "-",
        "Clients that hold at least one device notification (project)",
    ),
    ObjectTemplate(
        "cnc_cycle_jitter_p50_r", Scope.PLATFORM, COM, COM_CH, 0x1019, UNS32, R, "us",
        "Median lateness of a cycle start against its deadline, to 10 us, since start or "
        "cnc_cycle_stats_reset_w; 0 with the virtual clock (project)",
    ),
    ObjectTemplate(
        "cnc_cycle_jitter_p99_r", Scope.PLATFORM, COM, COM_CH, 0x101A, UNS32, R, "us",
        "99th percentile of the lateness of a cycle start, to 10 us, since start or "
        "cnc_cycle_stats_reset_w; 0 with the virtual clock (project)",
    ),
    ObjectTemplate(
        "cnc_cycle_stats_reset_w", Scope.PLATFORM, COM, COM_CH, 0x101B, BOOLEAN, W, "-",
        "TRUE: the cycle figures (overruns, jitter max/p50/p99, longest execution) start "
        "again from zero, for a measurement (project)",
    ),
    ObjectTemplate(
        "cnc_cycle_step_w", Scope.PLATFORM, COM, COM_CH, 0x1020, UNS32, W, "-",
        "Step clock (--clock step): N runs N cycles (1..[limits] step_max_cycles); the "
        "reply comes after the N-th cycle is published. Refused 0x707 under another "
        "clock (project)",
    ),
    ObjectTemplate(
        "cnc_cycle_sched_policy_r", Scope.PLATFORM, COM, COM_CH, 0x1030, UNS16, R, "-",
        "Scheduling policy the cycle thread got: 0 SCHED_OTHER (virtual clock, real-time "
        "priority off or refused), 1 SCHED_FIFO (realtime clock, --rt-priority) (project)",
    ),
    ObjectTemplate(
        "cnc_cycle_sched_priority_r", Scope.PLATFORM, COM, COM_CH, 0x1031, UNS16, R, "-",
        "SCHED_FIFO priority of the cycle thread (1..99); 0 under SCHED_OTHER (project)",
    ),
    ObjectTemplate(
        "cnc_memory_locked_r", Scope.PLATFORM, COM, COM_CH, 0x1032, BOOLEAN, R, "-",
        "TRUE when the service's memory is locked in RAM (mlockall, with SCHED_FIFO) "
        "(project)",
    ),
    # --- COM platform axes (offsets as TwinSharp, 0x120200 / 0x<ANo>00xx) ---------------
    ObjectTemplate(
        "command_position_acs", Scope.PHYSICAL_AXIS, COM, COM_AX, 0x02, SGN32, R, "0.1 um",
        "Command position of the drive in the axis coordinate system",
    ),
    ObjectTemplate(
        "actual_position_acs", Scope.PHYSICAL_AXIS, COM, COM_AX, 0x03, SGN32, R, "0.1 um",
        "Actual position of the drive in the axis coordinate system",
    ),
    ObjectTemplate(
        "axis_name", Scope.PHYSICAL_AXIS, COM, COM_AX, 0x09, STRING(16), R, "-",
        "Name of the physical axis (offset as TwinSharp)",
    ),
    ObjectTemplate(
        "link_to_logical_axis", Scope.PHYSICAL_AXIS, COM, COM_AX, 0x0F, UNS16, R, "-",
        "Logical axis number that drives this physical axis; 0 = none (project offset)",
    ),
    # --- COM platform: axis parameter update (project) ------------------------------------
    # --- #MSG message list and high-speed settings (CYCLES-ADC; project offsets) ----------
    ObjectTemplate(
        "mc_message_count_r", Scope.CHANNEL, COM, COM_CH, 0x3200, UNS32, R, "-",
        "#MSG texts of the program since its start; the newest 8 are in "
        "mc_message_<k>_text_r (project)",
    ),
    *(
        ObjectTemplate(
            f"mc_message_{k}_text_r", Scope.CHANNEL, COM, COM_CH, 0x3200 + k, STRING(256), R,
            "-", f"#MSG text {k} of the message list, 1 = newest; empty = none (project)",
        )
        for k in range(1, MESSAGES_LISTED + 1)
    ),
    *(
        ObjectTemplate(f"{name}_r", Scope.CHANNEL, COM, COM_CH, 0x3210 + n, dtype, R, unit,
                       f"{meaning}, as decoded so far; a program start resets it (project)")
        for n, (name, _attr, dtype, unit, meaning) in enumerate(MACHINING_FIELDS)
    ),
    # --- syntax check parameters (FCT-C9; channel list values, writable; project offsets)
    ObjectTemplate(
        "syn_chk.errors_total", Scope.CHANNEL, COM, COM_CH, 0x3100, UNS16, RW, "-",
        "P-CHAN-00019: the syntax check ends after this many errors, 0 = no limit; from "
        "the next program start (project)",
    ),
    ObjectTemplate(
        "syn_chk.errors_per_block", Scope.CHANNEL, COM, COM_CH, 0x3101, UNS16, RW, "-",
        "P-CHAN-00020: errors in one NC line after which the check goes on with the next "
        "line, 0 = no limit (project)",
    ),
    ObjectTemplate(
        "syn_chk.interactive", Scope.CHANNEL, COM, COM_CH, 0x3102, BOOLEAN, RW, "-",
        "P-CHAN-00028: TRUE = stop in HOLD after each error until START or RESET (project)",
    ),
    ObjectTemplate(
        "syn_chk.record_result", Scope.CHANNEL, COM, COM_CH, 0x3103, BOOLEAN, RW, "-",
        "P-CHAN-00416: TRUE = write every checked line and error to dec0<c>.sc in the "
        "output area (project)",
    ),
    ObjectTemplate(
        "prod_time_trace", Scope.CHANNEL, COM, COM_CH, 0x3110, BOOLEAN, RW, "-",
        "TRUE: the next PROD_TIME run (machining time calculation) writes its path, one "
        "row per cycle, to prodtime0<c>.csv in the output area; cnc plot uses it (project)",
    ),
    ObjectTemplate(
        "axis_parameter_update_w", Scope.PLATFORM, COM, COM_CH, 0x1100, STRING(4096), W, "-",
        "Write an ISG axis parameter list (kopf.achs_nr first): changes that axis's "
        "parameters from the next program start; clones keep theirs (project)",
    ),
    # --- PLC (HLI) per channel: gpCh[i] (port 851) ---------------------------------------
    ObjectTemplate(
        "bahn_mc_control.suspend_axis_output.command_w", Scope.PLC_CHANNEL, PLC, PLC_GROUP,
        0x100, BOOLEAN, RW, "-",
        "TRUE: suspend the channel's output to the physical axes (evaluated while enable_w)",
    ),
    ObjectTemplate(
        "bahn_mc_control.suspend_axis_output.enable_w", Scope.PLC_CHANNEL, PLC, PLC_GROUP,
        0x101, BOOLEAN, RW, "-",
        "TRUE: the CNC follows command_w; FALSE: it follows request_r",
    ),
    ObjectTemplate(
        "bahn_mc_control.suspend_axis_output.request_r", Scope.PLC_CHANNEL, PLC, PLC_GROUP,
        0x102, BOOLEAN, R, "-",
        "The CNC side's own request (the configured suspend_output_at_start)",
    ),
    ObjectTemplate(
        "bahn_mc_control.suspend_axis_output.state_r", Scope.PLC_CHANNEL, PLC, PLC_GROUP,
        0x103, BOOLEAN, R, "-",
        "TRUE while the channel's axis output is suspended (its axes are given up)",
    ),
    ObjectTemplate(
        # before coord_r (PLC_COORD_BASE): bahn_state's members lie together (issue 41)
        "bahn_state.dist_prog_start", Scope.PLC_CHANNEL, PLC, PLC_GROUP, 0xE38, REAL64, R,
        "0.1 um", "Path distance covered since program start or #DISTANCE PROG START CLEAR, "
        "on the compensated path",
    ),
    # execution mode control unit (FCT-C9), MC_CONTROL_SGN32_UNIT
    ObjectTemplate(
        "decoder_mc_control.execution_mode.command_w", Scope.PLC_CHANNEL, PLC, PLC_GROUP,
        0x120, SGN32, RW, "-",
        "Execution mode the PLC commands (evaluated at program start while enable_w)",
    ),
    ObjectTemplate(
        "decoder_mc_control.execution_mode.enable_w", Scope.PLC_CHANNEL, PLC, PLC_GROUP,
        0x124, BOOLEAN, RW, "-",
        "TRUE: a program start takes command_w; FALSE: the HMI's request (request_r)",
    ),
    ObjectTemplate(
        "decoder_mc_control.execution_mode.request_r", Scope.PLC_CHANNEL, PLC, PLC_GROUP,
        0x128, SGN32, R, "-", "Execution mode the HMI requests (mc_command_execution_mode_w)",
    ),
    ObjectTemplate(
        "decoder_mc_control.execution_mode.state_r", Scope.PLC_CHANNEL, PLC, PLC_GROUP,
        0x12C, SGN32, R, "-", "Execution mode in effect (SYNCHK implies MACHINE_LOCK and "
        "SUPPRESS_TECHNO_OUTPUT)",
    ),
    # decoder display flags (FCT-C9), pMC[i]^.addr^.StateDecoder_Data
    *(
        ObjectTemplate(
            f"StateDecoder_Data.{name}", Scope.PLC_MC, PLC, PLC_GROUP, 0x140 + n, BOOLEAN, R,
            "-", text,
        )
        for n, (name, text) in enumerate((
            ("X_SyntaxCheck", "The decoder works in the syntax check"),
            ("X_WaitAfterError", "Syntax check: the decoder waits after an error for "
             "continue (START) or abort (RESET)"),
            ("X_SyntaxCheckReleaseNextBlockCleared", "Syntax check: after an error and the "
             "enable to go on, the decoder waits until the enable is cancelled (one cycle: "
             "the service cancels it)"),
            ("X_WaitContinue", "Decoding is interrupted (single step, STOP) and waits for "
             "the enable to go on"),
            ("X_WaitReleaseNextBlockCleared", "Decoding goes on after an interruption and "
             "waits until the enable is cancelled (one cycle)"),
        ))
    ),
    # contour look-ahead control unit (FCT-C40), HLI_CONTOUR_LOOKAHEAD
    ObjectTemplate(
        "contour_lookahead.request.start_position", Scope.PLC_CHANNEL, PLC, PLC_GROUP, 0x200,
        REAL64, RW, "-", "Mode 1 (length 0): index of the first element in the marked area; "
        "mode 2: start of the path window (0.1 um)",
    ),
    ObjectTemplate(
        "contour_lookahead.request.length", Scope.PLC_CHANNEL, PLC, PLC_GROUP, 0x208, REAL64,
        RW, "0.1 um", "0: request by index (mode 1); else length of the path window (mode 2)",
    ),
    ObjectTemplate(
        "contour_lookahead.semaphor_rw", Scope.PLC_CHANNEL, PLC, PLC_GROUP, 0x210, BOOLEAN, RW,
        "-", "TRUE: the PLC requests; the CNC fills the response and resets it to FALSE",
    ),
    ObjectTemplate(
        "contour_lookahead.state.max_dist_prog_start", Scope.PLC_CHANNEL, PLC, PLC_GROUP,
        0x218, REAL64, R, "0.1 um",
        "Maximum look-ahead distance from program start: end of the path prepared so far",
    ),
    ObjectTemplate(
        "contour_lookahead.state.count_logged_blocks", Scope.PLC_CHANNEL, PLC, PLC_GROUP,
        0x220, UNS32, R, "-", "Entries in the log of the marked area (readable by index)",
    ),
    ObjectTemplate(
        "contour_lookahead.state.f_log_is_active", Scope.PLC_CHANNEL, PLC, PLC_GROUP, 0x224,
        BOOLEAN, R, "-", "TRUE while the marked area is open and not all of it is read in",
    ),
    *(
        ObjectTemplate(
            f"contour_lookahead.response.block[{k}].{name}", Scope.PLC_CHANNEL, PLC,
            PLC_GROUP, CONTOUR_RESPONSE_OFFSET + k * CONTOUR_BLOCK_STRIDE + offset, dtype, R,
            unit, f"Reply entry {k}: {text}", CONTOUR_BLOCK_VALUES.get(name),
        )
        for k in range(CONTOUR_RESPONSE_BLOCKS)
        for name, offset, dtype, unit, text in CONTOUR_BLOCK_FIELDS
    ),
    # --- PLC (HLI) per axis slot: gpAx[i] (port 851) -------------------------------------
    ObjectTemplate(
        "head.log_ax_n_r", Scope.PLC_AXIS, PLC, PLC_GROUP, 0x00, UNS16, R, "-",
        "Axis number of this HLI axis slot",
    ),
    ObjectTemplate(
        "lr_state.position_offset_r", Scope.PLC_AXIS, PLC, PLC_GROUP, 0x10, SGN32, R, "0.1 um",
        "Offset between the logical axis linked to this physical axis and the physical "
        "position (command - actual); 0 when none is linked",
    ),
    ObjectTemplate(
        "lr_state.link_to_ipo_r", Scope.PLC_AXIS, PLC, PLC_GROUP, 0x14, UNS16, R, "-",
        "Logical axis that drives this physical axis; 0 = not linked",
    ),
    ObjectTemplate(
        "ipo_state.link_to_lr", Scope.PLC_AXIS, PLC, PLC_GROUP, 0x40, UNS16, R, "-",
        "Physical axis this logical axis outputs to; 0 = not linked",
    ),
)



def core_templates(sizes: CatalogSizes) -> tuple[ObjectTemplate, ...]:
    """The platform's, drives', channels' and axes' own objects (this module's rows)."""
    return CORE_TEMPLATES


#: The catalog's areas in the order their objects are listed. Each is a function of the
#: machine's table sizes giving its templates; a new area is a module with one such
#: function, named here (its bindings go in ``service.binding``'s list of the same areas).
AREAS: tuple[Callable[[CatalogSizes], tuple[ObjectTemplate, ...]], ...] = (
    core_templates,
    technology_templates,  # technology output and spindle (catalog_technology)
    manual_templates,  # manual mode and homing (catalog_manual)
    operator_templates,  # operator switches, machine state, settings (catalog_operator)
    tool_templates,  # tools and work offsets, as many as configured (catalog_tools)
    alarm_templates,  # alarms, as many history slots as the log keeps (catalog_alarms)
)


NO_TABLES = CatalogSizes()  # the fixed objects only: no tool rows, offsets, history


def templates(sizes: CatalogSizes = NO_TABLES) -> tuple[ObjectTemplate, ...]:
    """Every template of the catalog for a machine with table sizes ``sizes``."""
    return tuple(t for area in AREAS for t in area(sizes))


def build_objects(
    layout: MachineLayout, sizes: CatalogSizes = NO_TABLES
) -> list[CncObject]:
    """Every object instance of ``layout`` (with tables of ``sizes``)."""
    return instances(layout, templates(sizes))
