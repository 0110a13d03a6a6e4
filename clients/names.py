"""Every object name of the catalog as a typed path (generated: do not edit).

Made by ``tools/gen_names.py`` from the object catalog (``make generate``); a test fails
when it is stale. A plain step is an attribute, a numbered one a call::

    from cnc_objects.clients import names

    names.ch(1).mc_active_state_r            # "ch1.mc_active_state_r"
    names.ch(1).ax(2).manual_increment_w     # "ch1.ax2.manual_increment_w"
    names.ch(1).wz(3).radius                 # "ch1.wz[3].radius"
    names.cnc_tick_counter_r                 # "cnc_tick_counter_r"

Each is the ``str`` the service knows, so it goes wherever a name goes
(``client.read(names.ch(1).mc_active_state_r)``); a misspelt step is a mypy error. A step
that is a Python keyword ends in ``_`` (``alarm_active(1).class_`` is ``...class``).
"""

from __future__ import annotations

from typing import Final


class _AlarmActive:
    """Objects below ``alarm_active``."""

    __slots__ = ("_prefix",)

    def __init__(self, prefix: str) -> None:
        self._prefix = prefix

    @property
    def channel(self) -> str:
        return self._prefix + "channel"

    @property
    def class_(self) -> str:
        return self._prefix + "class"

    @property
    def column(self) -> str:
        return self._prefix + "column"

    @property
    def cycle(self) -> str:
        return self._prefix + "cycle"

    @property
    def file(self) -> str:
        return self._prefix + "file"

    @property
    def id(self) -> str:
        return self._prefix + "id"

    @property
    def kernel_time(self) -> str:
        return self._prefix + "kernel_time"

    @property
    def line(self) -> str:
        return self._prefix + "line"

    @property
    def sequence(self) -> str:
        return self._prefix + "sequence"

    @property
    def severity(self) -> str:
        return self._prefix + "severity"

    @property
    def state(self) -> str:
        return self._prefix + "state"

    @property
    def text(self) -> str:
        return self._prefix + "text"

    @property
    def time(self) -> str:
        return self._prefix + "time"


class _AlarmHistory:
    """Objects below ``alarm_history``."""

    __slots__ = ("_prefix",)

    def __init__(self, prefix: str) -> None:
        self._prefix = prefix

    @property
    def channel(self) -> str:
        return self._prefix + "channel"

    @property
    def class_(self) -> str:
        return self._prefix + "class"

    @property
    def column(self) -> str:
        return self._prefix + "column"

    @property
    def cycle(self) -> str:
        return self._prefix + "cycle"

    @property
    def file(self) -> str:
        return self._prefix + "file"

    @property
    def id(self) -> str:
        return self._prefix + "id"

    @property
    def kernel_time(self) -> str:
        return self._prefix + "kernel_time"

    @property
    def line(self) -> str:
        return self._prefix + "line"

    @property
    def sequence(self) -> str:
        return self._prefix + "sequence"

    @property
    def severity(self) -> str:
        return self._prefix + "severity"

    @property
    def state(self) -> str:
        return self._prefix + "state"

    @property
    def text(self) -> str:
        return self._prefix + "text"

    @property
    def time(self) -> str:
        return self._prefix + "time"


class _Ax:
    """Objects below ``ax``."""

    __slots__ = ("_prefix",)

    def __init__(self, prefix: str) -> None:
        self._prefix = prefix

    @property
    def actual_position_acs(self) -> str:
        return self._prefix + "actual_position_acs"

    @property
    def axis_name(self) -> str:
        return self._prefix + "axis_name"

    @property
    def command_position_acs(self) -> str:
        return self._prefix + "command_position_acs"

    @property
    def link_to_logical_axis(self) -> str:
        return self._prefix + "link_to_logical_axis"


class _ChAxNpGrp:
    """Objects below ``ch.ax.np_grp``."""

    __slots__ = ("_prefix",)

    def __init__(self, prefix: str) -> None:
        self._prefix = prefix

    @property
    def v(self) -> str:
        return self._prefix + "v"


class _ChAx:
    """Objects below ``ch.ax``."""

    __slots__ = ("_prefix",)

    def __init__(self, prefix: str) -> None:
        self._prefix = prefix

    def np_grp(self, index: int) -> _ChAxNpGrp:
        """``np_grp[index].``."""
        return _ChAxNpGrp(self._prefix + f"np_grp[{index}].")

    @property
    def acc_max(self) -> str:
        return self._prefix + "acc_max"

    @property
    def actual_link_to_physical_axis(self) -> str:
        return self._prefix + "actual_link_to_physical_axis"

    @property
    def actual_position_pcs(self) -> str:
        return self._prefix + "actual_position_pcs"

    @property
    def axis_name(self) -> str:
        return self._prefix + "axis_name"

    @property
    def axis_type(self) -> str:
        return self._prefix + "axis_type"

    @property
    def command_position_acs(self) -> str:
        return self._prefix + "command_position_acs"

    @property
    def command_position_pcs(self) -> str:
        return self._prefix + "command_position_pcs"

    @property
    def distance_to_go_pcs(self) -> str:
        return self._prefix + "distance_to_go_pcs"

    @property
    def homing_active_r(self) -> str:
        return self._prefix + "homing_active_r"

    @property
    def homing_referenced_r(self) -> str:
        return self._prefix + "homing_referenced_r"

    @property
    def homing_start_w(self) -> str:
        return self._prefix + "homing_start_w"

    @property
    def link_state(self) -> str:
        return self._prefix + "link_state"

    @property
    def logical_axis_number(self) -> str:
        return self._prefix + "logical_axis_number"

    @property
    def manual_handwheel_counter_w(self) -> str:
        return self._prefix + "manual_handwheel_counter_w"

    @property
    def manual_hr_aufloesung_w(self) -> str:
        return self._prefix + "manual_hr_aufloesung_w"

    @property
    def manual_increment_w(self) -> str:
        return self._prefix + "manual_increment_w"

    @property
    def manual_jog_minus_w(self) -> str:
        return self._prefix + "manual_jog_minus_w"

    @property
    def manual_jog_plus_w(self) -> str:
        return self._prefix + "manual_jog_plus_w"

    @property
    def manual_limit_warning_r(self) -> str:
        return self._prefix + "manual_limit_warning_r"

    @property
    def manual_moving_r(self) -> str:
        return self._prefix + "manual_moving_r"

    @property
    def manual_offset_r(self) -> str:
        return self._prefix + "manual_offset_r"

    @property
    def manual_operation_mode_w(self) -> str:
        return self._prefix + "manual_operation_mode_w"

    @property
    def manual_rapid_w(self) -> str:
        return self._prefix + "manual_rapid_w"

    @property
    def manual_velocity_r(self) -> str:
        return self._prefix + "manual_velocity_r"

    @property
    def position_offset(self) -> str:
        return self._prefix + "position_offset"

    @property
    def requested_link_to_physical_axis(self) -> str:
        return self._prefix + "requested_link_to_physical_axis"

    @property
    def vel_jump_max(self) -> str:
        return self._prefix + "vel_jump_max"

    @property
    def vel_max(self) -> str:
        return self._prefix + "vel_max"


class _ChSynChk:
    """Objects below ``ch.syn_chk``."""

    __slots__ = ("_prefix",)

    def __init__(self, prefix: str) -> None:
        self._prefix = prefix

    @property
    def errors_per_block(self) -> str:
        return self._prefix + "errors_per_block"

    @property
    def errors_total(self) -> str:
        return self._prefix + "errors_total"

    @property
    def interactive(self) -> str:
        return self._prefix + "interactive"

    @property
    def record_result(self) -> str:
        return self._prefix + "record_result"


class _ChWz:
    """Objects below ``ch.wz``."""

    __slots__ = ("_prefix",)

    def __init__(self, prefix: str) -> None:
        self._prefix = prefix

    @property
    def laenge(self) -> str:
        return self._prefix + "laenge"

    @property
    def life_expired(self) -> str:
        return self._prefix + "life_expired"

    @property
    def life_max(self) -> str:
        return self._prefix + "life_max"

    @property
    def life_used(self) -> str:
        return self._prefix + "life_used"

    @property
    def name(self) -> str:
        return self._prefix + "name"

    @property
    def radius(self) -> str:
        return self._prefix + "radius"

    @property
    def valid(self) -> str:
        return self._prefix + "valid"

    @property
    def wear(self) -> str:
        return self._prefix + "wear"


class _Ch:
    """Objects below ``ch``."""

    __slots__ = ("_prefix",)

    def __init__(self, prefix: str) -> None:
        self._prefix = prefix

    def ax(self, index: int) -> _ChAx:
        """``ax<index>.``."""
        return _ChAx(self._prefix + f"ax{index}.")

    @property
    def syn_chk(self) -> _ChSynChk:
        return _ChSynChk(self._prefix + "syn_chk.")

    def wz(self, index: int) -> _ChWz:
        """``wz[index].``."""
        return _ChWz(self._prefix + f"wz[{index}].")

    @property
    def acc_weight_r(self) -> str:
        return self._prefix + "acc_weight_r"

    @property
    def active_zero_offset_group(self) -> str:
        return self._prefix + "active_zero_offset_group"

    @property
    def actual_block_count(self) -> str:
        return self._prefix + "actual_block_count"

    @property
    def actual_block_number(self) -> str:
        return self._prefix + "actual_block_number"

    @property
    def actual_path_velocity(self) -> str:
        return self._prefix + "actual_path_velocity"

    @property
    def actual_tool_radius(self) -> str:
        return self._prefix + "actual_tool_radius"

    @property
    def dist_prog_start(self) -> str:
        return self._prefix + "dist_prog_start"

    @property
    def filter_active_r(self) -> str:
        return self._prefix + "filter_active_r"

    @property
    def filter_ax_dev_r(self) -> str:
        return self._prefix + "filter_ax_dev_r"

    @property
    def hsc_active_r(self) -> str:
        return self._prefix + "hsc_active_r"

    @property
    def hsc_path_dev_r(self) -> str:
        return self._prefix + "hsc_path_dev_r"

    @property
    def hsc_surface_r(self) -> str:
        return self._prefix + "hsc_surface_r"

    @property
    def hsc_track_dev_r(self) -> str:
        return self._prefix + "hsc_track_dev_r"

    @property
    def lookahead_blocks(self) -> str:
        return self._prefix + "lookahead_blocks"

    @property
    def mc_active_block_ignore_r(self) -> str:
        return self._prefix + "mc_active_block_ignore_r"

    @property
    def mc_active_execution_mode_r(self) -> str:
        return self._prefix + "mc_active_execution_mode_r"

    @property
    def mc_active_feed_override_r(self) -> str:
        return self._prefix + "mc_active_feed_override_r"

    @property
    def mc_active_feedrate_r(self) -> str:
        return self._prefix + "mc_active_feedrate_r"

    @property
    def mc_active_file_name_r(self) -> str:
        return self._prefix + "mc_active_file_name_r"

    @property
    def mc_active_file_offset_r(self) -> str:
        return self._prefix + "mc_active_file_offset_r"

    @property
    def mc_active_line_r(self) -> str:
        return self._prefix + "mc_active_line_r"

    @property
    def mc_active_mode_r(self) -> str:
        return self._prefix + "mc_active_mode_r"

    @property
    def mc_active_program_name_r(self) -> str:
        return self._prefix + "mc_active_program_name_r"

    @property
    def mc_active_rapid_override_r(self) -> str:
        return self._prefix + "mc_active_rapid_override_r"

    @property
    def mc_active_single_block_r(self) -> str:
        return self._prefix + "mc_active_single_block_r"

    @property
    def mc_active_state_r(self) -> str:
        return self._prefix + "mc_active_state_r"

    @property
    def mc_active_tool_length_r(self) -> str:
        return self._prefix + "mc_active_tool_length_r"

    @property
    def mc_active_tool_offset_r(self) -> str:
        return self._prefix + "mc_active_tool_offset_r"

    @property
    def mc_active_tool_r(self) -> str:
        return self._prefix + "mc_active_tool_r"

    @property
    def mc_active_tool_radius_r(self) -> str:
        return self._prefix + "mc_active_tool_radius_r"

    @property
    def mc_active_zero_offset_r(self) -> str:
        return self._prefix + "mc_active_zero_offset_r"

    @property
    def mc_all_axes_referenced_r(self) -> str:
        return self._prefix + "mc_all_axes_referenced_r"

    @property
    def mc_block_count_r(self) -> str:
        return self._prefix + "mc_block_count_r"

    @property
    def mc_command_M01_stop_enable_r(self) -> str:
        return self._prefix + "mc_command_M01_stop_enable_r"

    @property
    def mc_command_M01_stop_enable_w(self) -> str:
        return self._prefix + "mc_command_M01_stop_enable_w"

    @property
    def mc_command_block_ignore_r(self) -> str:
        return self._prefix + "mc_command_block_ignore_r"

    @property
    def mc_command_block_ignore_w(self) -> str:
        return self._prefix + "mc_command_block_ignore_w"

    @property
    def mc_command_execution_mode_r(self) -> str:
        return self._prefix + "mc_command_execution_mode_r"

    @property
    def mc_command_execution_mode_w(self) -> str:
        return self._prefix + "mc_command_execution_mode_w"

    @property
    def mc_command_feed_override_r(self) -> str:
        return self._prefix + "mc_command_feed_override_r"

    @property
    def mc_command_feed_override_w(self) -> str:
        return self._prefix + "mc_command_feed_override_w"

    @property
    def mc_command_feedrate_r(self) -> str:
        return self._prefix + "mc_command_feedrate_r"

    @property
    def mc_command_hold_w(self) -> str:
        return self._prefix + "mc_command_hold_w"

    @property
    def mc_command_manual_block_w(self) -> str:
        return self._prefix + "mc_command_manual_block_w"

    @property
    def mc_command_mode_w(self) -> str:
        return self._prefix + "mc_command_mode_w"

    @property
    def mc_command_program_name_w(self) -> str:
        return self._prefix + "mc_command_program_name_w"

    @property
    def mc_command_rapid_override_r(self) -> str:
        return self._prefix + "mc_command_rapid_override_r"

    @property
    def mc_command_rapid_override_w(self) -> str:
        return self._prefix + "mc_command_rapid_override_w"

    @property
    def mc_command_reset_w(self) -> str:
        return self._prefix + "mc_command_reset_w"

    @property
    def mc_command_single_block_w(self) -> str:
        return self._prefix + "mc_command_single_block_w"

    @property
    def mc_command_start_w(self) -> str:
        return self._prefix + "mc_command_start_w"

    @property
    def mc_coolant_state_r(self) -> str:
        return self._prefix + "mc_coolant_state_r"

    @property
    def mc_error_1_column_r(self) -> str:
        return self._prefix + "mc_error_1_column_r"

    @property
    def mc_error_1_file_r(self) -> str:
        return self._prefix + "mc_error_1_file_r"

    @property
    def mc_error_1_id_r(self) -> str:
        return self._prefix + "mc_error_1_id_r"

    @property
    def mc_error_1_line_r(self) -> str:
        return self._prefix + "mc_error_1_line_r"

    @property
    def mc_error_1_text_r(self) -> str:
        return self._prefix + "mc_error_1_text_r"

    @property
    def mc_error_1_warning_r(self) -> str:
        return self._prefix + "mc_error_1_warning_r"

    @property
    def mc_error_2_column_r(self) -> str:
        return self._prefix + "mc_error_2_column_r"

    @property
    def mc_error_2_file_r(self) -> str:
        return self._prefix + "mc_error_2_file_r"

    @property
    def mc_error_2_id_r(self) -> str:
        return self._prefix + "mc_error_2_id_r"

    @property
    def mc_error_2_line_r(self) -> str:
        return self._prefix + "mc_error_2_line_r"

    @property
    def mc_error_2_text_r(self) -> str:
        return self._prefix + "mc_error_2_text_r"

    @property
    def mc_error_2_warning_r(self) -> str:
        return self._prefix + "mc_error_2_warning_r"

    @property
    def mc_error_3_column_r(self) -> str:
        return self._prefix + "mc_error_3_column_r"

    @property
    def mc_error_3_file_r(self) -> str:
        return self._prefix + "mc_error_3_file_r"

    @property
    def mc_error_3_id_r(self) -> str:
        return self._prefix + "mc_error_3_id_r"

    @property
    def mc_error_3_line_r(self) -> str:
        return self._prefix + "mc_error_3_line_r"

    @property
    def mc_error_3_text_r(self) -> str:
        return self._prefix + "mc_error_3_text_r"

    @property
    def mc_error_3_warning_r(self) -> str:
        return self._prefix + "mc_error_3_warning_r"

    @property
    def mc_error_4_column_r(self) -> str:
        return self._prefix + "mc_error_4_column_r"

    @property
    def mc_error_4_file_r(self) -> str:
        return self._prefix + "mc_error_4_file_r"

    @property
    def mc_error_4_id_r(self) -> str:
        return self._prefix + "mc_error_4_id_r"

    @property
    def mc_error_4_line_r(self) -> str:
        return self._prefix + "mc_error_4_line_r"

    @property
    def mc_error_4_text_r(self) -> str:
        return self._prefix + "mc_error_4_text_r"

    @property
    def mc_error_4_warning_r(self) -> str:
        return self._prefix + "mc_error_4_warning_r"

    @property
    def mc_error_5_column_r(self) -> str:
        return self._prefix + "mc_error_5_column_r"

    @property
    def mc_error_5_file_r(self) -> str:
        return self._prefix + "mc_error_5_file_r"

    @property
    def mc_error_5_id_r(self) -> str:
        return self._prefix + "mc_error_5_id_r"

    @property
    def mc_error_5_line_r(self) -> str:
        return self._prefix + "mc_error_5_line_r"

    @property
    def mc_error_5_text_r(self) -> str:
        return self._prefix + "mc_error_5_text_r"

    @property
    def mc_error_5_warning_r(self) -> str:
        return self._prefix + "mc_error_5_warning_r"

    @property
    def mc_error_6_column_r(self) -> str:
        return self._prefix + "mc_error_6_column_r"

    @property
    def mc_error_6_file_r(self) -> str:
        return self._prefix + "mc_error_6_file_r"

    @property
    def mc_error_6_id_r(self) -> str:
        return self._prefix + "mc_error_6_id_r"

    @property
    def mc_error_6_line_r(self) -> str:
        return self._prefix + "mc_error_6_line_r"

    @property
    def mc_error_6_text_r(self) -> str:
        return self._prefix + "mc_error_6_text_r"

    @property
    def mc_error_6_warning_r(self) -> str:
        return self._prefix + "mc_error_6_warning_r"

    @property
    def mc_error_7_column_r(self) -> str:
        return self._prefix + "mc_error_7_column_r"

    @property
    def mc_error_7_file_r(self) -> str:
        return self._prefix + "mc_error_7_file_r"

    @property
    def mc_error_7_id_r(self) -> str:
        return self._prefix + "mc_error_7_id_r"

    @property
    def mc_error_7_line_r(self) -> str:
        return self._prefix + "mc_error_7_line_r"

    @property
    def mc_error_7_text_r(self) -> str:
        return self._prefix + "mc_error_7_text_r"

    @property
    def mc_error_7_warning_r(self) -> str:
        return self._prefix + "mc_error_7_warning_r"

    @property
    def mc_error_8_column_r(self) -> str:
        return self._prefix + "mc_error_8_column_r"

    @property
    def mc_error_8_file_r(self) -> str:
        return self._prefix + "mc_error_8_file_r"

    @property
    def mc_error_8_id_r(self) -> str:
        return self._prefix + "mc_error_8_id_r"

    @property
    def mc_error_8_line_r(self) -> str:
        return self._prefix + "mc_error_8_line_r"

    @property
    def mc_error_8_text_r(self) -> str:
        return self._prefix + "mc_error_8_text_r"

    @property
    def mc_error_8_warning_r(self) -> str:
        return self._prefix + "mc_error_8_warning_r"

    @property
    def mc_error_count_r(self) -> str:
        return self._prefix + "mc_error_count_r"

    @property
    def mc_feed_override_max_r(self) -> str:
        return self._prefix + "mc_feed_override_max_r"

    @property
    def mc_g00_override_mode_r(self) -> str:
        return self._prefix + "mc_g00_override_mode_r"

    @property
    def mc_manual_blocks_done_r(self) -> str:
        return self._prefix + "mc_manual_blocks_done_r"

    @property
    def mc_message_1_text_r(self) -> str:
        return self._prefix + "mc_message_1_text_r"

    @property
    def mc_message_2_text_r(self) -> str:
        return self._prefix + "mc_message_2_text_r"

    @property
    def mc_message_3_text_r(self) -> str:
        return self._prefix + "mc_message_3_text_r"

    @property
    def mc_message_4_text_r(self) -> str:
        return self._prefix + "mc_message_4_text_r"

    @property
    def mc_message_5_text_r(self) -> str:
        return self._prefix + "mc_message_5_text_r"

    @property
    def mc_message_6_text_r(self) -> str:
        return self._prefix + "mc_message_6_text_r"

    @property
    def mc_message_7_text_r(self) -> str:
        return self._prefix + "mc_message_7_text_r"

    @property
    def mc_message_8_text_r(self) -> str:
        return self._prefix + "mc_message_8_text_r"

    @property
    def mc_message_count_r(self) -> str:
        return self._prefix + "mc_message_count_r"

    @property
    def mc_plc_auto_acknowledge_r(self) -> str:
        return self._prefix + "mc_plc_auto_acknowledge_r"

    @property
    def mc_referencing_required_r(self) -> str:
        return self._prefix + "mc_referencing_required_r"

    @property
    def mc_selected_tool_r(self) -> str:
        return self._prefix + "mc_selected_tool_r"

    @property
    def mc_spindle_active_rev_r(self) -> str:
        return self._prefix + "mc_spindle_active_rev_r"

    @property
    def mc_spindle_cmd_rev_r(self) -> str:
        return self._prefix + "mc_spindle_cmd_rev_r"

    @property
    def mc_spindle_mode_r(self) -> str:
        return self._prefix + "mc_spindle_mode_r"

    @property
    def mc_spindle_override_w(self) -> str:
        return self._prefix + "mc_spindle_override_w"

    @property
    def mc_spindle_position_r(self) -> str:
        return self._prefix + "mc_spindle_position_r"

    @property
    def mc_spindle_prog_rev_r(self) -> str:
        return self._prefix + "mc_spindle_prog_rev_r"

    @property
    def mc_spindle_speed_reached_r(self) -> str:
        return self._prefix + "mc_spindle_speed_reached_r"

    @property
    def mc_techno_0_command(self) -> str:
        return self._prefix + "mc_techno_0_command"

    @property
    def mc_techno_0_nr(self) -> str:
        return self._prefix + "mc_techno_0_nr"

    @property
    def mc_techno_0_state(self) -> str:
        return self._prefix + "mc_techno_0_state"

    @property
    def mc_techno_0_synch(self) -> str:
        return self._prefix + "mc_techno_0_synch"

    @property
    def mc_techno_0_typ(self) -> str:
        return self._prefix + "mc_techno_0_typ"

    @property
    def mc_techno_10_command(self) -> str:
        return self._prefix + "mc_techno_10_command"

    @property
    def mc_techno_10_nr(self) -> str:
        return self._prefix + "mc_techno_10_nr"

    @property
    def mc_techno_10_state(self) -> str:
        return self._prefix + "mc_techno_10_state"

    @property
    def mc_techno_10_synch(self) -> str:
        return self._prefix + "mc_techno_10_synch"

    @property
    def mc_techno_10_typ(self) -> str:
        return self._prefix + "mc_techno_10_typ"

    @property
    def mc_techno_11_command(self) -> str:
        return self._prefix + "mc_techno_11_command"

    @property
    def mc_techno_11_nr(self) -> str:
        return self._prefix + "mc_techno_11_nr"

    @property
    def mc_techno_11_state(self) -> str:
        return self._prefix + "mc_techno_11_state"

    @property
    def mc_techno_11_synch(self) -> str:
        return self._prefix + "mc_techno_11_synch"

    @property
    def mc_techno_11_typ(self) -> str:
        return self._prefix + "mc_techno_11_typ"

    @property
    def mc_techno_12_command(self) -> str:
        return self._prefix + "mc_techno_12_command"

    @property
    def mc_techno_12_nr(self) -> str:
        return self._prefix + "mc_techno_12_nr"

    @property
    def mc_techno_12_state(self) -> str:
        return self._prefix + "mc_techno_12_state"

    @property
    def mc_techno_12_synch(self) -> str:
        return self._prefix + "mc_techno_12_synch"

    @property
    def mc_techno_12_typ(self) -> str:
        return self._prefix + "mc_techno_12_typ"

    @property
    def mc_techno_13_command(self) -> str:
        return self._prefix + "mc_techno_13_command"

    @property
    def mc_techno_13_nr(self) -> str:
        return self._prefix + "mc_techno_13_nr"

    @property
    def mc_techno_13_state(self) -> str:
        return self._prefix + "mc_techno_13_state"

    @property
    def mc_techno_13_synch(self) -> str:
        return self._prefix + "mc_techno_13_synch"

    @property
    def mc_techno_13_typ(self) -> str:
        return self._prefix + "mc_techno_13_typ"

    @property
    def mc_techno_14_command(self) -> str:
        return self._prefix + "mc_techno_14_command"

    @property
    def mc_techno_14_nr(self) -> str:
        return self._prefix + "mc_techno_14_nr"

    @property
    def mc_techno_14_state(self) -> str:
        return self._prefix + "mc_techno_14_state"

    @property
    def mc_techno_14_synch(self) -> str:
        return self._prefix + "mc_techno_14_synch"

    @property
    def mc_techno_14_typ(self) -> str:
        return self._prefix + "mc_techno_14_typ"

    @property
    def mc_techno_15_command(self) -> str:
        return self._prefix + "mc_techno_15_command"

    @property
    def mc_techno_15_nr(self) -> str:
        return self._prefix + "mc_techno_15_nr"

    @property
    def mc_techno_15_state(self) -> str:
        return self._prefix + "mc_techno_15_state"

    @property
    def mc_techno_15_synch(self) -> str:
        return self._prefix + "mc_techno_15_synch"

    @property
    def mc_techno_15_typ(self) -> str:
        return self._prefix + "mc_techno_15_typ"

    @property
    def mc_techno_1_command(self) -> str:
        return self._prefix + "mc_techno_1_command"

    @property
    def mc_techno_1_nr(self) -> str:
        return self._prefix + "mc_techno_1_nr"

    @property
    def mc_techno_1_state(self) -> str:
        return self._prefix + "mc_techno_1_state"

    @property
    def mc_techno_1_synch(self) -> str:
        return self._prefix + "mc_techno_1_synch"

    @property
    def mc_techno_1_typ(self) -> str:
        return self._prefix + "mc_techno_1_typ"

    @property
    def mc_techno_2_command(self) -> str:
        return self._prefix + "mc_techno_2_command"

    @property
    def mc_techno_2_nr(self) -> str:
        return self._prefix + "mc_techno_2_nr"

    @property
    def mc_techno_2_state(self) -> str:
        return self._prefix + "mc_techno_2_state"

    @property
    def mc_techno_2_synch(self) -> str:
        return self._prefix + "mc_techno_2_synch"

    @property
    def mc_techno_2_typ(self) -> str:
        return self._prefix + "mc_techno_2_typ"

    @property
    def mc_techno_3_command(self) -> str:
        return self._prefix + "mc_techno_3_command"

    @property
    def mc_techno_3_nr(self) -> str:
        return self._prefix + "mc_techno_3_nr"

    @property
    def mc_techno_3_state(self) -> str:
        return self._prefix + "mc_techno_3_state"

    @property
    def mc_techno_3_synch(self) -> str:
        return self._prefix + "mc_techno_3_synch"

    @property
    def mc_techno_3_typ(self) -> str:
        return self._prefix + "mc_techno_3_typ"

    @property
    def mc_techno_4_command(self) -> str:
        return self._prefix + "mc_techno_4_command"

    @property
    def mc_techno_4_nr(self) -> str:
        return self._prefix + "mc_techno_4_nr"

    @property
    def mc_techno_4_state(self) -> str:
        return self._prefix + "mc_techno_4_state"

    @property
    def mc_techno_4_synch(self) -> str:
        return self._prefix + "mc_techno_4_synch"

    @property
    def mc_techno_4_typ(self) -> str:
        return self._prefix + "mc_techno_4_typ"

    @property
    def mc_techno_5_command(self) -> str:
        return self._prefix + "mc_techno_5_command"

    @property
    def mc_techno_5_nr(self) -> str:
        return self._prefix + "mc_techno_5_nr"

    @property
    def mc_techno_5_state(self) -> str:
        return self._prefix + "mc_techno_5_state"

    @property
    def mc_techno_5_synch(self) -> str:
        return self._prefix + "mc_techno_5_synch"

    @property
    def mc_techno_5_typ(self) -> str:
        return self._prefix + "mc_techno_5_typ"

    @property
    def mc_techno_6_command(self) -> str:
        return self._prefix + "mc_techno_6_command"

    @property
    def mc_techno_6_nr(self) -> str:
        return self._prefix + "mc_techno_6_nr"

    @property
    def mc_techno_6_state(self) -> str:
        return self._prefix + "mc_techno_6_state"

    @property
    def mc_techno_6_synch(self) -> str:
        return self._prefix + "mc_techno_6_synch"

    @property
    def mc_techno_6_typ(self) -> str:
        return self._prefix + "mc_techno_6_typ"

    @property
    def mc_techno_7_command(self) -> str:
        return self._prefix + "mc_techno_7_command"

    @property
    def mc_techno_7_nr(self) -> str:
        return self._prefix + "mc_techno_7_nr"

    @property
    def mc_techno_7_state(self) -> str:
        return self._prefix + "mc_techno_7_state"

    @property
    def mc_techno_7_synch(self) -> str:
        return self._prefix + "mc_techno_7_synch"

    @property
    def mc_techno_7_typ(self) -> str:
        return self._prefix + "mc_techno_7_typ"

    @property
    def mc_techno_8_command(self) -> str:
        return self._prefix + "mc_techno_8_command"

    @property
    def mc_techno_8_nr(self) -> str:
        return self._prefix + "mc_techno_8_nr"

    @property
    def mc_techno_8_state(self) -> str:
        return self._prefix + "mc_techno_8_state"

    @property
    def mc_techno_8_synch(self) -> str:
        return self._prefix + "mc_techno_8_synch"

    @property
    def mc_techno_8_typ(self) -> str:
        return self._prefix + "mc_techno_8_typ"

    @property
    def mc_techno_9_command(self) -> str:
        return self._prefix + "mc_techno_9_command"

    @property
    def mc_techno_9_nr(self) -> str:
        return self._prefix + "mc_techno_9_nr"

    @property
    def mc_techno_9_state(self) -> str:
        return self._prefix + "mc_techno_9_state"

    @property
    def mc_techno_9_synch(self) -> str:
        return self._prefix + "mc_techno_9_synch"

    @property
    def mc_techno_9_typ(self) -> str:
        return self._prefix + "mc_techno_9_typ"

    @property
    def mc_tool_list_size_r(self) -> str:
        return self._prefix + "mc_tool_list_size_r"

    @property
    def mc_wait_reason_r(self) -> str:
        return self._prefix + "mc_wait_reason_r"

    @property
    def mc_wait_reason_text_r(self) -> str:
        return self._prefix + "mc_wait_reason_text_r"

    @property
    def mc_waiting_for_start_r(self) -> str:
        return self._prefix + "mc_waiting_for_start_r"

    @property
    def mc_zero_offset_groups_r(self) -> str:
        return self._prefix + "mc_zero_offset_groups_r"

    @property
    def prod_time_trace(self) -> str:
        return self._prefix + "prod_time_trace"

    @property
    def program_time(self) -> str:
        return self._prefix + "program_time"

    @property
    def programmed_path_velocity(self) -> str:
        return self._prefix + "programmed_path_velocity"

    @property
    def ramp_weight_r(self) -> str:
        return self._prefix + "ramp_weight_r"

    @property
    def remaining_path_in_block(self) -> str:
        return self._prefix + "remaining_path_in_block"

    @property
    def slope_type_r(self) -> str:
        return self._prefix + "slope_type_r"

    @property
    def trafo_active_r(self) -> str:
        return self._prefix + "trafo_active_r"


class _GpAxHead:
    """Objects below ``gpAx.head``."""

    __slots__ = ("_prefix",)

    def __init__(self, prefix: str) -> None:
        self._prefix = prefix

    @property
    def log_ax_n_r(self) -> str:
        return self._prefix + "log_ax_n_r"


class _GpAxIpoState:
    """Objects below ``gpAx.ipo_state``."""

    __slots__ = ("_prefix",)

    def __init__(self, prefix: str) -> None:
        self._prefix = prefix

    @property
    def link_to_lr(self) -> str:
        return self._prefix + "link_to_lr"


class _GpAxLrState:
    """Objects below ``gpAx.lr_state``."""

    __slots__ = ("_prefix",)

    def __init__(self, prefix: str) -> None:
        self._prefix = prefix

    @property
    def link_to_ipo_r(self) -> str:
        return self._prefix + "link_to_ipo_r"

    @property
    def position_offset_r(self) -> str:
        return self._prefix + "position_offset_r"


class _GpAx:
    """Objects below ``gpAx``."""

    __slots__ = ("_prefix",)

    def __init__(self, prefix: str) -> None:
        self._prefix = prefix

    @property
    def head(self) -> _GpAxHead:
        return _GpAxHead(self._prefix + "head.")

    @property
    def ipo_state(self) -> _GpAxIpoState:
        return _GpAxIpoState(self._prefix + "ipo_state.")

    @property
    def lr_state(self) -> _GpAxLrState:
        return _GpAxLrState(self._prefix + "lr_state.")


class _GpChBahnMcControlSuspendAxisOutput:
    """Objects below ``gpCh.bahn_mc_control.suspend_axis_output``."""

    __slots__ = ("_prefix",)

    def __init__(self, prefix: str) -> None:
        self._prefix = prefix

    @property
    def command_w(self) -> str:
        return self._prefix + "command_w"

    @property
    def enable_w(self) -> str:
        return self._prefix + "enable_w"

    @property
    def request_r(self) -> str:
        return self._prefix + "request_r"

    @property
    def state_r(self) -> str:
        return self._prefix + "state_r"


class _GpChBahnMcControl:
    """Objects below ``gpCh.bahn_mc_control``."""

    __slots__ = ("_prefix",)

    def __init__(self, prefix: str) -> None:
        self._prefix = prefix

    @property
    def suspend_axis_output(self) -> _GpChBahnMcControlSuspendAxisOutput:
        return _GpChBahnMcControlSuspendAxisOutput(self._prefix + "suspend_axis_output.")


class _GpChBahnStateCoordRHbDisplayR:
    """Objects below ``gpCh.bahn_state.coord_r.hb_display_r``."""

    __slots__ = ("_prefix",)

    def __init__(self, prefix: str) -> None:
        self._prefix = prefix

    @property
    def control_element(self) -> str:
        return self._prefix + "control_element"

    @property
    def hr_aufloesung(self) -> str:
        return self._prefix + "hr_aufloesung"

    @property
    def operation_mode(self) -> str:
        return self._prefix + "operation_mode"

    @property
    def state(self) -> str:
        return self._prefix + "state"

    @property
    def tipp_geschw(self) -> str:
        return self._prefix + "tipp_geschw"


class _GpChBahnStateCoordR:
    """Objects below ``gpCh.bahn_state.coord_r``."""

    __slots__ = ("_prefix",)

    def __init__(self, prefix: str) -> None:
        self._prefix = prefix

    @property
    def hb_display_r(self) -> _GpChBahnStateCoordRHbDisplayR:
        return _GpChBahnStateCoordRHbDisplayR(self._prefix + "hb_display_r.")


class _GpChBahnState:
    """Objects below ``gpCh.bahn_state``."""

    __slots__ = ("_prefix",)

    def __init__(self, prefix: str) -> None:
        self._prefix = prefix

    def coord_r(self, index: int) -> _GpChBahnStateCoordR:
        """``coord_r[index].``."""
        return _GpChBahnStateCoordR(self._prefix + f"coord_r[{index}].")

    @property
    def dist_prog_start(self) -> str:
        return self._prefix + "dist_prog_start"


class _GpChContourLookaheadRequest:
    """Objects below ``gpCh.contour_lookahead.request``."""

    __slots__ = ("_prefix",)

    def __init__(self, prefix: str) -> None:
        self._prefix = prefix

    @property
    def length(self) -> str:
        return self._prefix + "length"

    @property
    def start_position(self) -> str:
        return self._prefix + "start_position"


class _GpChContourLookaheadResponseBlock:
    """Objects below ``gpCh.contour_lookahead.response.block``."""

    __slots__ = ("_prefix",)

    def __init__(self, prefix: str) -> None:
        self._prefix = prefix

    @property
    def block_count_r(self) -> str:
        return self._prefix + "block_count_r"

    @property
    def block_number(self) -> str:
        return self._prefix + "block_number"

    @property
    def block_type(self) -> str:
        return self._prefix + "block_type"

    @property
    def circle_angle(self) -> str:
        return self._prefix + "circle_angle"

    @property
    def compensated_radius(self) -> str:
        return self._prefix + "compensated_radius"

    @property
    def length(self) -> str:
        return self._prefix + "length"

    @property
    def length_min(self) -> str:
        return self._prefix + "length_min"

    @property
    def programmed_radius(self) -> str:
        return self._prefix + "programmed_radius"

    @property
    def start_position(self) -> str:
        return self._prefix + "start_position"

    @property
    def tangent_variation(self) -> str:
        return self._prefix + "tangent_variation"


class _GpChContourLookaheadResponse:
    """Objects below ``gpCh.contour_lookahead.response``."""

    __slots__ = ("_prefix",)

    def __init__(self, prefix: str) -> None:
        self._prefix = prefix

    def block(self, index: int) -> _GpChContourLookaheadResponseBlock:
        """``block[index].``."""
        return _GpChContourLookaheadResponseBlock(self._prefix + f"block[{index}].")


class _GpChContourLookaheadState:
    """Objects below ``gpCh.contour_lookahead.state``."""

    __slots__ = ("_prefix",)

    def __init__(self, prefix: str) -> None:
        self._prefix = prefix

    @property
    def count_logged_blocks(self) -> str:
        return self._prefix + "count_logged_blocks"

    @property
    def f_log_is_active(self) -> str:
        return self._prefix + "f_log_is_active"

    @property
    def max_dist_prog_start(self) -> str:
        return self._prefix + "max_dist_prog_start"


class _GpChContourLookahead:
    """Objects below ``gpCh.contour_lookahead``."""

    __slots__ = ("_prefix",)

    def __init__(self, prefix: str) -> None:
        self._prefix = prefix

    @property
    def request(self) -> _GpChContourLookaheadRequest:
        return _GpChContourLookaheadRequest(self._prefix + "request.")

    @property
    def response(self) -> _GpChContourLookaheadResponse:
        return _GpChContourLookaheadResponse(self._prefix + "response.")

    @property
    def state(self) -> _GpChContourLookaheadState:
        return _GpChContourLookaheadState(self._prefix + "state.")

    @property
    def semaphor_rw(self) -> str:
        return self._prefix + "semaphor_rw"


class _GpChDecoderMcControlExecutionMode:
    """Objects below ``gpCh.decoder_mc_control.execution_mode``."""

    __slots__ = ("_prefix",)

    def __init__(self, prefix: str) -> None:
        self._prefix = prefix

    @property
    def command_w(self) -> str:
        return self._prefix + "command_w"

    @property
    def enable_w(self) -> str:
        return self._prefix + "enable_w"

    @property
    def request_r(self) -> str:
        return self._prefix + "request_r"

    @property
    def state_r(self) -> str:
        return self._prefix + "state_r"


class _GpChDecoderMcControlProgramBlockIgnore:
    """Objects below ``gpCh.decoder_mc_control.program_block_ignore``."""

    __slots__ = ("_prefix",)

    def __init__(self, prefix: str) -> None:
        self._prefix = prefix

    @property
    def command_w(self) -> str:
        return self._prefix + "command_w"

    @property
    def enable_w(self) -> str:
        return self._prefix + "enable_w"

    @property
    def request_r(self) -> str:
        return self._prefix + "request_r"

    @property
    def state_r(self) -> str:
        return self._prefix + "state_r"


class _GpChDecoderMcControl:
    """Objects below ``gpCh.decoder_mc_control``."""

    __slots__ = ("_prefix",)

    def __init__(self, prefix: str) -> None:
        self._prefix = prefix

    @property
    def execution_mode(self) -> _GpChDecoderMcControlExecutionMode:
        return _GpChDecoderMcControlExecutionMode(self._prefix + "execution_mode.")

    @property
    def program_block_ignore(self) -> _GpChDecoderMcControlProgramBlockIgnore:
        return _GpChDecoderMcControlProgramBlockIgnore(self._prefix + "program_block_ignore.")


class _GpChSpindle:
    """Objects below ``gpCh.spindle``."""

    __slots__ = ("_prefix",)

    def __init__(self, prefix: str) -> None:
        self._prefix = prefix

    @property
    def active_rev_r(self) -> str:
        return self._prefix + "active_rev_r"

    @property
    def cmd_rev_r(self) -> str:
        return self._prefix + "cmd_rev_r"

    @property
    def mode_r(self) -> str:
        return self._prefix + "mode_r"

    @property
    def override_w(self) -> str:
        return self._prefix + "override_w"

    @property
    def position_r(self) -> str:
        return self._prefix + "position_r"

    @property
    def prog_rev_r(self) -> str:
        return self._prefix + "prog_rev_r"

    @property
    def speed_reached_r(self) -> str:
        return self._prefix + "speed_reached_r"


class _GpChTechnoUnitStdSyncAttributR:
    """Objects below ``gpCh.techno_unit_std_sync.attribut_r``."""

    __slots__ = ("_prefix",)

    def __init__(self, prefix: str) -> None:
        self._prefix = prefix

    @property
    def nr(self) -> str:
        return self._prefix + "nr"

    @property
    def synch(self) -> str:
        return self._prefix + "synch"

    @property
    def typ(self) -> str:
        return self._prefix + "typ"


class _GpChTechnoUnitStdSync:
    """Objects below ``gpCh.techno_unit_std_sync``."""

    __slots__ = ("_prefix",)

    def __init__(self, prefix: str) -> None:
        self._prefix = prefix

    @property
    def attribut_r(self) -> _GpChTechnoUnitStdSyncAttributR:
        return _GpChTechnoUnitStdSyncAttributR(self._prefix + "attribut_r.")

    @property
    def command_w(self) -> str:
        return self._prefix + "command_w"

    @property
    def state_r(self) -> str:
        return self._prefix + "state_r"


class _GpCh:
    """Objects below ``gpCh``."""

    __slots__ = ("_prefix",)

    def __init__(self, prefix: str) -> None:
        self._prefix = prefix

    @property
    def bahn_mc_control(self) -> _GpChBahnMcControl:
        return _GpChBahnMcControl(self._prefix + "bahn_mc_control.")

    @property
    def bahn_state(self) -> _GpChBahnState:
        return _GpChBahnState(self._prefix + "bahn_state.")

    @property
    def contour_lookahead(self) -> _GpChContourLookahead:
        return _GpChContourLookahead(self._prefix + "contour_lookahead.")

    @property
    def decoder_mc_control(self) -> _GpChDecoderMcControl:
        return _GpChDecoderMcControl(self._prefix + "decoder_mc_control.")

    @property
    def spindle(self) -> _GpChSpindle:
        return _GpChSpindle(self._prefix + "spindle.")

    def techno_unit_std_sync(self, index: int) -> _GpChTechnoUnitStdSync:
        """``techno_unit_std_sync[index].``."""
        return _GpChTechnoUnitStdSync(self._prefix + f"techno_unit_std_sync[{index}].")

    @property
    def used_units_std_sync_r(self) -> str:
        return self._prefix + "used_units_std_sync_r"


class _PMCStateDecoderData:
    """Objects below ``pMC.StateDecoder_Data``."""

    __slots__ = ("_prefix",)

    def __init__(self, prefix: str) -> None:
        self._prefix = prefix

    @property
    def X_SyntaxCheck(self) -> str:
        return self._prefix + "X_SyntaxCheck"

    @property
    def X_SyntaxCheckReleaseNextBlockCleared(self) -> str:
        return self._prefix + "X_SyntaxCheckReleaseNextBlockCleared"

    @property
    def X_WaitAfterError(self) -> str:
        return self._prefix + "X_WaitAfterError"

    @property
    def X_WaitContinue(self) -> str:
        return self._prefix + "X_WaitContinue"

    @property
    def X_WaitReleaseNextBlockCleared(self) -> str:
        return self._prefix + "X_WaitReleaseNextBlockCleared"


class _PMC:
    """Objects below ``pMC``."""

    __slots__ = ("_prefix",)

    def __init__(self, prefix: str) -> None:
        self._prefix = prefix

    @property
    def StateDecoder_Data(self) -> _PMCStateDecoderData:
        return _PMCStateDecoderData(self._prefix + "StateDecoder_Data.")



def alarm_active(index: int) -> _AlarmActive:
    """``alarm_active[index].``."""
    return _AlarmActive(f"alarm_active[{index}].")


def alarm_history(index: int) -> _AlarmHistory:
    """``alarm_history[index].``."""
    return _AlarmHistory(f"alarm_history[{index}].")


def ax(index: int) -> _Ax:
    """``ax<index>.``."""
    return _Ax(f"ax{index}.")


def ch(index: int) -> _Ch:
    """``ch<index>.``."""
    return _Ch(f"ch{index}.")


def gpAx(index: int) -> _GpAx:
    """``gpAx[index].``."""
    return _GpAx(f"gpAx[{index}].")


def gpCh(index: int) -> _GpCh:
    """``gpCh[index].``."""
    return _GpCh(f"gpCh[{index}].")


def pMC(index: int) -> _PMC:
    """``pMC[index].``."""
    return _PMC(f"pMC[{index}].")


alarm_acknowledge_all_w: Final = "alarm_acknowledge_all_w"
alarm_acknowledge_w: Final = "alarm_acknowledge_w"
alarm_active_count_r: Final = "alarm_active_count_r"
alarm_changes_r: Final = "alarm_changes_r"
alarm_history_count_r: Final = "alarm_history_count_r"
alarm_raised_r: Final = "alarm_raised_r"
axis_parameter_update_w: Final = "axis_parameter_update_w"
cnc_cycle_exec_time_max_r: Final = "cnc_cycle_exec_time_max_r"
cnc_cycle_jitter_max_r: Final = "cnc_cycle_jitter_max_r"
cnc_cycle_jitter_p50_r: Final = "cnc_cycle_jitter_p50_r"
cnc_cycle_jitter_p99_r: Final = "cnc_cycle_jitter_p99_r"
cnc_cycle_overruns_r: Final = "cnc_cycle_overruns_r"
cnc_cycle_sched_policy_r: Final = "cnc_cycle_sched_policy_r"
cnc_cycle_sched_priority_r: Final = "cnc_cycle_sched_priority_r"
cnc_cycle_stats_reset_w: Final = "cnc_cycle_stats_reset_w"
cnc_cycle_step_w: Final = "cnc_cycle_step_w"
cnc_cycle_time_r: Final = "cnc_cycle_time_r"
cnc_kernel_running_r: Final = "cnc_kernel_running_r"
cnc_kernel_time_r: Final = "cnc_kernel_time_r"
cnc_memory_locked_r: Final = "cnc_memory_locked_r"
cnc_notification_clients_r: Final = "cnc_notification_clients_r"
cnc_notifications_r: Final = "cnc_notifications_r"
cnc_number_of_axis_r: Final = "cnc_number_of_axis_r"
cnc_number_of_channel_r: Final = "cnc_number_of_channel_r"
cnc_plc_acknowledges_r: Final = "cnc_plc_acknowledges_r"
cnc_programs_need_referenced_axes_r: Final = "cnc_programs_need_referenced_axes_r"
cnc_tick_counter_r: Final = "cnc_tick_counter_r"
cnc_tool_change_time_r: Final = "cnc_tool_change_time_r"
cnc_version_r: Final = "cnc_version_r"
