"""Binds the operator's switches, the channel's machine state and the settings objects
(objects.catalog_operator) to the kernel: reads from the snapshot or the configuration,
writes as kernel commands (kernel.operator_switches)."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from cnc_objects.objects import CncObject

from .binding_types import AreaBinding, Binder, Getter, WriteBinder
from .kernel.commands import Command
from .kernel.commands_operator import (
    SetBlockIgnore,
    SetBlockIgnorePlc,
    SetBlockIgnorePlcEnable,
    SetM01StopEnable,
    SetRapidOverride,
)
from .kernel.kernel import Kernel
from .kernel.state import Channel


def _of_channel(value: Callable[[Channel], Any]) -> Binder:
    def bind(kernel: Kernel, obj: CncObject) -> Getter:
        ci = kernel.channel_index(obj.channel)
        return lambda: value(kernel.snapshot.channels[ci])

    return bind


def _all_referenced(ch: Channel) -> bool:
    return all(view.referenced for view in ch.manual)


def _referencing_required(kernel: Kernel, obj: CncObject) -> Getter:
    """TRUE while an axis of the channel that needs homing (P-AXIS-00277, its own or
    the machine's default) is not referenced: a program may not move it yet."""
    ci = kernel.channel_index(obj.channel)
    config = kernel.config
    default = config.programs_need_referenced_axes
    needs = tuple(default if a.manual.prog_move_requires_homing is None
                  else a.manual.prog_move_requires_homing for a in config.channels[ci].axes)
    return lambda: any(need and not view.referenced for need, view in
                       zip(needs, kernel.snapshot.channels[ci].manual, strict=False))


def _distance_to_go(kernel: Kernel, obj: CncObject) -> Getter:
    ci, ai = kernel.channel_index(obj.channel), obj.axis - 1
    return lambda: kernel.snapshot.channels[ci].axes[ai].distance_to_go_01um


def _configured(value: Callable[[Kernel, CncObject], Any]) -> Binder:
    """A setting: constant while the service runs."""
    def bind(kernel: Kernel, obj: CncObject) -> Getter:
        fixed = value(kernel, obj)
        return lambda: fixed

    return bind


def _channel_config(kernel: Kernel, obj: CncObject) -> Any:
    return kernel.config.channels[kernel.channel_index(obj.channel)]


OPERATOR_READERS: dict[str, Binder] = {
    "mc_command_block_ignore_r": _of_channel(lambda ch: ch.switches.block_ignore_command),
    "mc_active_block_ignore_r": _of_channel(lambda ch: ch.program.block_ignore_active),
    "mc_command_M01_stop_enable_r": _of_channel(lambda ch: ch.switches.m01_stop_enable),
    "decoder_mc_control.program_block_ignore.command_w": _of_channel(
        lambda ch: ch.switches.block_ignore_plc_command),
    "decoder_mc_control.program_block_ignore.enable_w": _of_channel(
        lambda ch: ch.switches.block_ignore_plc_enable),
    "decoder_mc_control.program_block_ignore.request_r": _of_channel(
        lambda ch: ch.switches.block_ignore_command),
    "decoder_mc_control.program_block_ignore.state_r": _of_channel(
        lambda ch: ch.program.block_ignore_active),
    "mc_command_rapid_override_r": _of_channel(lambda ch: ch.switches.rapid_override_command),
    "mc_active_rapid_override_r": _of_channel(lambda ch: ch.switches.rapid_override_per_mille),
    "mc_g00_override_mode_r": _of_channel(lambda ch: ch.switches.g00_override_mode),
    "mc_coolant_state_r": _of_channel(lambda ch: int(ch.plc_functions.coolant)),
    "mc_all_axes_referenced_r": _of_channel(_all_referenced),
    "mc_referencing_required_r": _referencing_required,
    "distance_to_go_pcs": _distance_to_go,
    "cnc_programs_need_referenced_axes_r": _configured(
        lambda k, o: k.config.programs_need_referenced_axes),
    "cnc_tool_change_time_r": _configured(lambda k, o: k.config.tool_change_time_s),
    "cnc_plc_acknowledges_r": _configured(lambda k, o: " ".join(k.config.plc.acknowledges)),
    "mc_feed_override_max_r": _configured(lambda k, o: _channel_config(k, o).feed_override_max),
    "mc_plc_auto_acknowledge_r": _configured(
        lambda k, o: _channel_config(k, o).techno.auto_acknowledge),
}


def _command(make: Callable[[int, Any], Command]) -> Callable[..., Callable[[Any], Command]]:
    def bind(kernel: Kernel, obj: CncObject) -> Callable[[Any], Command]:
        ci = kernel.channel_index(obj.channel)
        return lambda value: make(ci, value)

    return bind


OPERATOR_WRITERS: dict[str, WriteBinder] = {
    "mc_command_block_ignore_w": _command(SetBlockIgnore),
    "decoder_mc_control.program_block_ignore.command_w": _command(SetBlockIgnorePlc),
    "decoder_mc_control.program_block_ignore.enable_w": _command(SetBlockIgnorePlcEnable),
    "mc_command_M01_stop_enable_w": _command(SetM01StopEnable),
    "mc_command_rapid_override_w": _command(SetRapidOverride),
}


#: operator switches, machine state, settings (``objects.catalog_operator``)
BINDING = AreaBinding(lambda sizes: OPERATOR_READERS, lambda sizes: OPERATOR_WRITERS)
