"""Binds the catalog to the kernel: a getter on the snapshot and a command per object.

This is the one place that knows both an object's element name and where the kernel
keeps its value. Reads come from ``kernel.snapshot`` (the last published cycle); writes
become kernel commands, applied by the cycle thread before the reply is sent.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import partial
from operator import attrgetter
from typing import Any, TypeVar

from cnc_objects.objects import AddressSpace, ChannelLayout, CncObject, MachineLayout, build_objects
from cnc_objects.objects.addressing import LOGICAL_BIT, GroupBase, index_based
from cnc_objects.objects.catalog import CONTOUR_BLOCK_FIELDS, CONTOUR_RESPONSE_BLOCKS, MACHINING_FIELDS
from cnc_objects.objects.directory import ObjectDirectory
from cnc_objects.objects.templates import CatalogSizes
from cnc_objects.protocol.constants import CncPort
from cnc_objects.protocol.errors import AdsReturnCode
from cnc_objects.protocol.units import UM01_PER_MM
from cnc_objects.protocol.values import AXIS_TYPE_CODES, ERRORS_LISTED, MESSAGES_LISTED
from cnc_objects.protocol.wait_reasons import wait_reason_text

from . import __version__, binding_alarms, binding_manual, binding_operator, binding_technology, binding_tools
from .binding_types import AreaBinding, Binder, CommandFactory, Getter, WriteBinder
from .kernel.commands import (
    Command,
    Feedhold,
    ManualBlock,
    Refusal,
    RefusalReason,
    ResetChannel,
    SelectMode,
    SelectProgram,
    SetContourRequest,
    SetContourSemaphore,
    SetExecutionMode,
    SetExecutionModeEnable,
    SetExecutionModePlc,
    SetFeedOverride,
    SetProdTimeTrace,
    SetSingleBlock,
    SetSuspendCommand,
    SetSuspendEnable,
    SetSyntaxCheckParameter,
    StartProgram,
    UpdateAxisParameters,
)
from .kernel.kernel import Kernel, ResetCycleStats
from .kernel.state import DecoderFlag
from .kernel.step_clock import StepCycles
from .kernel.tooling import tool_list_size
from .machine_config import MachineConfig
from .notifications import NotificationCounts
from .param_list import ParamListError, parse_axis_list

REFUSAL_CODES: dict[RefusalReason, AdsReturnCode] = {
    RefusalReason.INVALID_VALUE: AdsReturnCode.DEVICE_INVALIDDATA,
    RefusalReason.NOT_READY: AdsReturnCode.DEVICE_NOTREADY,
    RefusalReason.BUSY: AdsReturnCode.DEVICE_BUSY,
    RefusalReason.NOT_FOUND: AdsReturnCode.DEVICE_NOTFOUND,
    RefusalReason.NOT_SUPPORTED: AdsReturnCode.DEVICE_SRVNOTSUPP,
}


_B = TypeVar("_B", Binder, WriteBinder)


def refusal_code(refusal: Refusal) -> AdsReturnCode:
    """The ADS code that answers a kernel refusal."""
    return REFUSAL_CODES[refusal.reason]


def _channel(path: str) -> Callable[[Kernel, CncObject], Getter]:
    """A value of a channel: ``path`` is a field (``"mode"``) or a part's field
    (``"block.line"``, see ``kernel.channel_parts``)."""
    get = attrgetter(path)

    def bind(kernel: Kernel, obj: CncObject) -> Getter:
        ci = kernel.channel_index(obj.channel)
        return lambda: get(kernel.snapshot.channels[ci])

    return bind


def _channel_axis(attr: str) -> Callable[[Kernel, CncObject], Getter]:
    def bind(kernel: Kernel, obj: CncObject) -> Getter:
        ci, ai = kernel.channel_index(obj.channel), obj.axis - 1
        return lambda: getattr(kernel.snapshot.channels[ci].axes[ai], attr)

    return bind


def _axis_type(kernel: Kernel, obj: CncObject) -> Getter:
    """kenngr.achs_typ of a channel axis: its configuration, fixed while running."""
    axis = kernel.config.channels[kernel.channel_index(obj.channel)].axes[obj.axis - 1]
    code = AXIS_TYPE_CODES[axis.axis_type]
    return lambda: code


def _physical_axis(attr: str) -> Callable[[Kernel, CncObject], Getter]:
    def bind(kernel: Kernel, obj: CncObject) -> Getter:
        index = [p.number for p in kernel.state.physical_axes].index(obj.axis)
        return lambda: getattr(kernel.snapshot.physical_axes[index], attr)

    return bind


def _stats(attr: str, wrap: Callable[[Any], Any] = lambda v: v) -> Callable[..., Getter]:
    def bind(kernel: Kernel, obj: CncObject) -> Getter:
        return lambda: wrap(getattr(kernel.snapshot.stats, attr))

    return bind


def _lateness(fraction: float) -> Callable[[Kernel, CncObject], Getter]:
    """A percentile of the cycle lateness. Read live from the clock's histogram, not from
    the snapshot: a figure of the cycle task about itself, summed over many cycles."""
    def bind(kernel: Kernel, obj: CncObject) -> Getter:
        lateness = kernel.lateness
        if lateness is None:  # the virtual clock has no deadlines
            return lambda: 0
        return lambda: min(lateness.percentile_us(fraction), 0xFFFFFFFF)

    return bind


def _realtime_grant(attr: str) -> Callable[[Kernel, CncObject], Getter]:
    """What the realtime clock's cycle thread was granted (``realtime_priority``), read
    live: the thread claims it when it starts. The virtual clock asks for nothing: 0."""
    def bind(kernel: Kernel, obj: CncObject) -> Getter:
        grant = kernel.realtime_grant
        if grant is None:
            return lambda: 0
        return lambda: int(getattr(grant, attr))

    return bind


def _constant(value: Callable[[Kernel], Any]) -> Callable[[Kernel, CncObject], Getter]:
    def bind(kernel: Kernel, obj: CncObject) -> Getter:
        fixed = value(kernel)
        return lambda: fixed

    return bind


def _constant_per_object(
    value: Callable[[Kernel, CncObject], Any],
) -> Callable[[Kernel, CncObject], Getter]:
    def bind(kernel: Kernel, obj: CncObject) -> Getter:
        fixed = value(kernel, obj)
        return lambda: fixed

    return bind


def _per_scope(
    physical: Callable[[Kernel, CncObject], Getter],
    channel_axis: Callable[[Kernel, CncObject], Getter],
) -> Callable[[Kernel, CncObject], Getter]:
    """One element name served for physical axes (no channel) and for channel axes."""

    def bind(kernel: Kernel, obj: CncObject) -> Getter:
        return (channel_axis if obj.channel else physical)(kernel, obj)

    return bind


def _channel_error(k: int, field: str) -> Callable[[Kernel, CncObject], Getter]:
    """Field of the k-th error of a channel's list; 0 / empty when there is none."""
    empty = {"text": "", "file": "", "warning": False}.get(field, 0)

    def bind(kernel: Kernel, obj: CncObject) -> Getter:
        ci = kernel.channel_index(obj.channel)

        def get() -> Any:
            errors = kernel.snapshot.channels[ci].errors.entries
            return getattr(errors[k - 1], field) if len(errors) >= k else empty

        return get

    return bind


def _channel_message(k: int) -> Callable[[Kernel, CncObject], Getter]:
    """The k-th newest #MSG text of a channel; empty when there is none."""
    def bind(kernel: Kernel, obj: CncObject) -> Getter:
        ci = kernel.channel_index(obj.channel)

        def get() -> str:
            messages = kernel.snapshot.channels[ci].program.messages
            return messages[k - 1] if len(messages) >= k else ""

        return get

    return bind


def _machining(attr: str) -> Callable[[Kernel, CncObject], Getter]:
    """A field of the channel's #HSC/#SLOPE/#FILTER/#TRAFO/G133/G134 settings."""
    def bind(kernel: Kernel, obj: CncObject) -> Getter:
        ci = kernel.channel_index(obj.channel)
        return lambda: getattr(kernel.snapshot.channels[ci].program.machining, attr)

    return bind


def _scaled(path: str, factor: float) -> Callable[[Kernel, CncObject], Getter]:
    """A value of a channel (``path`` as for ``_channel``) times ``factor``."""
    get = attrgetter(path)

    def bind(kernel: Kernel, obj: CncObject) -> Getter:
        ci = kernel.channel_index(obj.channel)
        return lambda: get(kernel.snapshot.channels[ci]) * factor

    return bind


def _axis_param(attr: str) -> Callable[[Kernel, CncObject], Getter]:
    """An effective axis parameter of a channel axis (clones resolved, updates seen)."""

    def bind(kernel: Kernel, obj: CncObject) -> Getter:
        number = kernel.config.channels[kernel.channel_index(obj.channel)].axes[obj.axis - 1]
        return lambda: getattr(kernel.axis_params[number.logical_number], attr)

    return bind


def _channel_config(attr: str) -> Callable[[Kernel, CncObject], Getter]:
    """A value of the channel's configuration (constant while the service runs)."""

    def bind(kernel: Kernel, obj: CncObject) -> Getter:
        value = getattr(kernel.config.channels[kernel.channel_index(obj.channel)], attr)
        return lambda: value

    return bind


def _hli_physical(attr: str) -> Callable[[Kernel, CncObject], Getter]:
    """``gpAx[i].lr_state``: the physical axis with the slot's number (0 when none)."""

    def bind(kernel: Kernel, obj: CncObject) -> Getter:
        if obj.axis not in {p.number for p in kernel.config.physical_axes}:
            return lambda: 0
        return _physical_axis(attr)(kernel, obj)

    return bind


def _hli_logical(attr: str) -> Callable[[Kernel, CncObject], Getter]:
    """``gpAx[i].ipo_state``: the logical axis with the slot's number (0 when none)."""

    def bind(kernel: Kernel, obj: CncObject) -> Getter:
        for ci, axis in kernel.config.startup_axes():
            if axis.logical_number == obj.axis:
                ai = kernel.config.channels[ci].axes.index(axis)
                return lambda: getattr(kernel.snapshot.channels[ci].axes[ai], attr)
        return lambda: 0

    return bind


def _contour(attr: str) -> Callable[[Kernel, CncObject], Getter]:
    """A field of ``gpCh[i].contour_lookahead`` (request, semaphore, state)."""

    def bind(kernel: Kernel, obj: CncObject) -> Getter:
        ci = kernel.channel_index(obj.channel)
        return lambda: getattr(kernel.snapshot.channels[ci].contour, attr)

    return bind


def _contour_block(k: int, field: str) -> Callable[[Kernel, CncObject], Getter]:
    """``response.block[k].<field>``: 0 beyond the reply's entries (block_type 0 ends
    the list)."""

    def bind(kernel: Kernel, obj: CncObject) -> Getter:
        ci = kernel.channel_index(obj.channel)

        def get() -> Any:
            response = kernel.snapshot.channels[ci].contour.response
            return getattr(response[k], field) if k < len(response) else 0

        return get

    return bind


def _kernel_time(kernel: Kernel, obj: CncObject) -> Getter:
    return lambda: kernel.snapshot.time_ns / 1e9


def _syn_chk(name: str) -> Callable[[Kernel, CncObject], Getter]:
    """``ch<c>.syn_chk.<name>``: the syntax check parameter for the next check."""

    def bind(kernel: Kernel, obj: CncObject) -> Getter:
        ci = kernel.channel_index(obj.channel)
        return lambda: getattr(kernel.snapshot.channels[ci].switches.syn_chk, name)

    return bind


def _wait_reason_text(kernel: Kernel, obj: CncObject) -> Getter:
    """``ch<c>.mc_wait_reason_text_r``: the sentence of the channel's wait reason."""
    ci = kernel.channel_index(obj.channel)
    return lambda: wait_reason_text(kernel.snapshot.channels[ci].wait_reason)


def _decoder_flag(flag: DecoderFlag) -> Callable[[Kernel, CncObject], Getter]:
    """``pMC[i].StateDecoder_Data.X_...``: one display flag of the decoder."""

    def bind(kernel: Kernel, obj: CncObject) -> Getter:
        ci = kernel.channel_index(obj.channel)
        return lambda: bool(kernel.snapshot.channels[ci].program.decoder_flags & flag)

    return bind


READERS: dict[str, Callable[[Kernel, CncObject], Getter]] = {
    "requested_link_to_physical_axis": _channel_axis("requested_link"),
    "actual_link_to_physical_axis": _channel_axis("actual_link"),
    "link_state": _channel_axis("link_state"),
    "dist_prog_start": _channel("path.dist_prog_start_01um"),
    "mc_command_feed_override_r": _channel("switches.feed_override_command"),
    "mc_active_feed_override_r": _channel("switches.feed_override_per_mille"),
    "mc_command_execution_mode_r": _channel("switches.execution_mode_command"),
    "decoder_mc_control.execution_mode.command_w": _channel("switches.execution_mode_plc_command"),
    "decoder_mc_control.execution_mode.enable_w": _channel("switches.execution_mode_plc_enable"),
    "decoder_mc_control.execution_mode.request_r": _channel("switches.execution_mode_command"),
    "decoder_mc_control.execution_mode.state_r": _channel("program.execution_mode_active"),
    "prod_time_trace": _channel("switches.prod_time_trace"),
    **{f"syn_chk.{name}": _syn_chk(name)
       for name in ("errors_total", "errors_per_block", "interactive", "record_result")},
    "StateDecoder_Data.X_SyntaxCheck": _decoder_flag(DecoderFlag.SYNTAX_CHECK),
    "StateDecoder_Data.X_WaitAfterError": _decoder_flag(DecoderFlag.WAIT_AFTER_ERROR),
    "StateDecoder_Data.X_SyntaxCheckReleaseNextBlockCleared": _decoder_flag(
        DecoderFlag.SYNTAX_CHECK_RELEASE_CLEARED),
    "StateDecoder_Data.X_WaitContinue": _decoder_flag(DecoderFlag.WAIT_CONTINUE),
    "StateDecoder_Data.X_WaitReleaseNextBlockCleared": _decoder_flag(
        DecoderFlag.WAIT_RELEASE_CLEARED),
    "mc_active_execution_mode_r": _channel("program.execution_mode_active"),
    "cnc_version_r": _constant(lambda k: f"cnc-objects {__version__}"),
    "cnc_number_of_channel_r": _constant(lambda k: len(k.config.channels)),
    "cnc_number_of_axis_r": _constant(lambda k: len(k.config.physical_axes)),
    "cnc_cycle_time_r": _stats("cycle_us"),
    "cnc_tick_counter_r": _stats("cycles", lambda v: v & 0xFFFFFFFF),
    "cnc_cycle_overruns_r": _stats("overruns", lambda v: min(v, 0xFFFFFFFF)),
    "cnc_cycle_jitter_max_r": _stats("jitter_max_us", lambda v: min(v, 0xFFFFFFFF)),
    "cnc_cycle_exec_time_max_r": _stats("exec_time_max_us", lambda v: min(v, 0xFFFFFFFF)),
    "cnc_kernel_time_r": _kernel_time,
    "cnc_kernel_running_r": _stats("running"),
    "cnc_cycle_jitter_p50_r": _lateness(0.5),
    "cnc_cycle_jitter_p99_r": _lateness(0.99),
    "cnc_cycle_sched_policy_r": _realtime_grant("policy"),
    "cnc_cycle_sched_priority_r": _realtime_grant("priority"),
    "cnc_memory_locked_r": _realtime_grant("memory_locked"),
    "command_position_acs": _per_scope(
        _physical_axis("command_position_01um"), _channel_axis("command_position_01um")
    ),
    "actual_position_acs": _physical_axis("actual_position_01um"),
    "link_to_logical_axis": _physical_axis("linked_logical_axis"),
    "axis_name": _per_scope(_physical_axis("name"), _channel_axis("name")),
    "logical_axis_number": _channel_axis("logical_number"),
    "axis_type": _axis_type,
    "remaining_path_in_block": _scaled("path.remaining_in_block_mm", UM01_PER_MM),
    "actual_path_velocity": _scaled("path.path_velocity_mm_s", 1e3),
    "programmed_path_velocity": _scaled("path.programmed_velocity_mm_s", 1e3),
    "actual_block_number": _channel("block.block_number"),
    "actual_block_count": _channel("block.block_count"),
    "mc_active_single_block_r": _channel("switches.single_block"),
    "mc_active_mode_r": _channel("mode"),
    "mc_active_state_r": _channel("state"),
    "mc_active_program_name_r": _channel("program.program_name"),
    "mc_active_file_name_r": _channel("block.file_name"),
    "mc_active_file_offset_r": _channel("block.file_offset"),
    "mc_active_line_r": _channel("block.line"),
    "mc_block_count_r": _channel("block.block_count"),
    "mc_command_feedrate_r": _scaled("path.programmed_velocity_mm_s", 1e3),
    "mc_active_feedrate_r": _scaled("path.path_velocity_mm_s", 1e3),
    "program_time": _channel("path.program_time_s"),
    "mc_waiting_for_start_r": _channel("program.waiting_for_start"),
    "mc_wait_reason_r": _channel("wait_reason"),
    "mc_wait_reason_text_r": _wait_reason_text,
    "mc_manual_blocks_done_r": _channel("block.manual_blocks_done"),
    "mc_error_count_r": _channel("errors.count"),
    "position_offset": _channel_axis("position_offset_01um"),
    "vel_max": _axis_param("vel_max_mm_s"),
    "acc_max": _axis_param("acc_max_mm_s2"),
    "vel_jump_max": _axis_param("vel_jump_mm_s"),
    "lookahead_blocks": _channel_config("look_ahead_blocks"),
    "bahn_mc_control.suspend_axis_output.command_w": _channel("suspend.command_w"),
    "bahn_mc_control.suspend_axis_output.enable_w": _channel("suspend.enable_w"),
    "bahn_mc_control.suspend_axis_output.request_r": _channel("suspend.request_r"),
    "bahn_mc_control.suspend_axis_output.state_r": _channel("suspend.output_suspended"),
    "bahn_state.dist_prog_start": _channel("path.dist_prog_start_01um"),
    "contour_lookahead.request.start_position": _contour("request_start_position"),
    "contour_lookahead.request.length": _contour("request_length"),
    "contour_lookahead.semaphor_rw": _contour("semaphor"),
    "contour_lookahead.state.max_dist_prog_start": _contour("max_dist_prog_start_01um"),
    "contour_lookahead.state.count_logged_blocks": _contour("count_logged_blocks"),
    "contour_lookahead.state.f_log_is_active": _contour("log_active"),
    **{
        f"contour_lookahead.response.block[{k}].{name}": _contour_block(k, name)
        for k in range(CONTOUR_RESPONSE_BLOCKS)
        for name, *_ in CONTOUR_BLOCK_FIELDS
    },
    "head.log_ax_n_r": _constant_per_object(lambda kernel, obj: obj.axis),
    "lr_state.position_offset_r": _hli_physical("position_offset_01um"),
    "lr_state.link_to_ipo_r": _hli_physical("linked_logical_axis"),
    "ipo_state.link_to_lr": _hli_logical("actual_link"),
    **{
        f"mc_error_{k}_{field}_r": _channel_error(k, field)
        for k in range(1, ERRORS_LISTED + 1)
        for field in ("id", "text", "file", "line", "column", "warning")
    },
    "mc_message_count_r": _channel("program.message_count"),
    **{f"mc_message_{k}_text_r": _channel_message(k) for k in range(1, MESSAGES_LISTED + 1)},
    **{f"{name}_r": _machining(attr) for name, attr, *_ in MACHINING_FIELDS},
}


#: Objects of the service around the kernel: bound to the notification hub's counts.
SERVICE_READERS: dict[str, Callable[[NotificationCounts], Getter]] = {
    "cnc_notifications_r": lambda counts: lambda: counts.total,
    "cnc_notification_clients_r": lambda counts: lambda: counts.clients,
}


def _syntax_check_parameter(name: str, ci: int, value: Any) -> Command:
    return SetSyntaxCheckParameter(ci, name, value)


def _channel_command(
    make: Callable[[int, Any], Command],
) -> Callable[[Kernel, CncObject], CommandFactory]:
    def bind(kernel: Kernel, obj: CncObject) -> CommandFactory:
        ci = kernel.channel_index(obj.channel)
        return lambda value: make(ci, value)

    return bind


WRITERS: dict[str, Callable[[Kernel, CncObject], CommandFactory]] = {
    "mc_command_feed_override_w": _channel_command(SetFeedOverride),
    "mc_command_execution_mode_w": _channel_command(SetExecutionMode),
    "decoder_mc_control.execution_mode.command_w": _channel_command(SetExecutionModePlc),
    "decoder_mc_control.execution_mode.enable_w": _channel_command(SetExecutionModeEnable),
    **{f"syn_chk.{name}": _channel_command(partial(_syntax_check_parameter, name))
       for name in ("errors_total", "errors_per_block", "interactive", "record_result")},
    "mc_command_single_block_w": _channel_command(SetSingleBlock),
    "prod_time_trace": _channel_command(SetProdTimeTrace),
    "mc_command_mode_w": _channel_command(SelectMode),
    "mc_command_program_name_w": _channel_command(SelectProgram),
    "mc_command_start_w": _channel_command(StartProgram),
    "mc_command_hold_w": _channel_command(Feedhold),
    "mc_command_reset_w": _channel_command(ResetChannel),
    "mc_command_manual_block_w": _channel_command(ManualBlock),
    "bahn_mc_control.suspend_axis_output.command_w": _channel_command(SetSuspendCommand),
    "bahn_mc_control.suspend_axis_output.enable_w": _channel_command(SetSuspendEnable),
    "axis_parameter_update_w": lambda kernel, obj: _axis_parameter_update,
    "cnc_cycle_stats_reset_w": lambda kernel, obj: ResetCycleStats,
    "cnc_cycle_step_w": lambda kernel, obj: StepCycles,
    "contour_lookahead.request.start_position": _channel_command(
        lambda ci, value: SetContourRequest(ci, "start_position", value)
    ),
    "contour_lookahead.request.length": _channel_command(
        lambda ci, value: SetContourRequest(ci, "length", value)
    ),
    "contour_lookahead.semaphor_rw": _channel_command(SetContourSemaphore),
}

#: The binders of the catalog's areas (``objects.catalog.AREAS``), in the same order:
#: this module's own (the core rows), then one module per area. A new area of objects
#: is one catalog module and one binding module, each named once in its list.
AREAS: tuple[AreaBinding, ...] = (
    AreaBinding(lambda sizes: READERS, lambda sizes: WRITERS),
    binding_technology.BINDING,
    binding_manual.BINDING,
    binding_operator.BINDING,
    binding_tools.BINDING,
    binding_alarms.BINDING,
)


def _merged(parts: list[dict[str, _B]], kind: str) -> dict[str, _B]:
    """One table of the areas' binders; an element bound by two areas is a bug."""
    merged: dict[str, _B] = {}
    for part in parts:
        twice = merged.keys() & part.keys()
        if twice:
            raise ValueError(f"{kind} bound twice: {', '.join(sorted(twice))}")
        merged |= part
    return merged


def area_readers(sizes: CatalogSizes) -> dict[str, Binder]:
    """The readers of every area, by element name."""
    return _merged([area.readers(sizes) for area in AREAS], "readers")


def area_writers(sizes: CatalogSizes) -> dict[str, WriteBinder]:
    """The writers of every area, by element name."""
    return _merged([area.writers(sizes) for area in AREAS], "writers")


def catalog_sizes(kernel: Kernel) -> CatalogSizes:
    """The table sizes of the kernel's machine: tool list rows, zero offset groups and
    alarm history slots."""
    return CatalogSizes(tool_list_size(kernel.config), kernel.config.zero_offset_groups,
                        kernel.alarms.history_max)


def _axis_parameter_update(text: str) -> Command:
    """Parse the list here (service side), apply it on the cycle thread."""
    try:
        return UpdateAxisParameters(parse_axis_list(text, "axis_parameter_update_w"))
    except ParamListError as exc:
        return UpdateAxisParameters(None, str(exc))


class LastWritten:
    """What a write-only command object (``mc_command_start_w``) reads: the value last
    written to it, its type's zero before any write, as a command variable of a TwinCAT
    PLC reads back. Every symbol of the upload is then readable, as in a PLC, and a read
    of a glob that takes in a command object does not fail as a whole.

    The value is kept once the kernel has applied the write: a write refused (0x706,
    0x707, ...) leaves the value before it, as a PLC variable that an error reply did
    not change. Kept and read on the event loop."""

    def __init__(self, obj: CncObject) -> None:
        self.value: Any = obj.dtype.decode(bytes(obj.dtype.size))

    def read(self) -> Any:
        """The value last written."""
        return self.value

    def keep(self, value: Any) -> None:
        """A write of ``value`` was applied."""
        self.value = value


def machine_layout(kernel: Kernel) -> MachineLayout:
    """The layout the catalog is expanded over, from the kernel's configuration."""
    return MachineLayout(
        channels=tuple(ChannelLayout(c.id, len(c.axes)) for c in kernel.config.channels),
        physical_axes=tuple(a.number for a in kernel.config.physical_axes),
        hli_axes=hli_axis_numbers(kernel.config),
    )


def hli_axis_numbers(config: MachineConfig) -> tuple[int, ...]:
    """Axis numbers of the HLI axis slots ``gpAx[0..]``: every physical and logical axis
    number, ascending. Slot i shows the physical axis with that number in ``lr_state``
    and the logical axis with that number in ``ipo_state``."""
    numbers = {a.number for a in config.physical_axes}
    numbers |= {a.logical_number for c in config.channels for a in c.axes}
    return tuple(sorted(numbers))


def _aliases(kernel: Kernel, obj: CncObject) -> list[int]:
    """Other groups that address ``obj``: the index-based spelling, platform under ch 1."""
    if obj.port == CncPort.PLC:
        return []  # PLC symbols have one address
    if obj.channel:
        return [index_based(obj.group, obj.channel, kernel.channel_index(obj.channel) + 1)]
    aliases = [obj.group & ~LOGICAL_BIT]
    if obj.group == GroupBase.COM_CHANNEL:  # platform data may be addressed as channel 1
        first = GroupBase.COM_CHANNEL + 1
        aliases += [first, first & ~LOGICAL_BIT]
    return aliases


def build_address_space(
    kernel: Kernel, notifications: NotificationCounts | None = None
) -> AddressSpace:
    """Every catalog object bound to ``kernel``, plus the COM object directories; the
    service's own figures read ``notifications`` (the hub's counts; zero without one)."""
    space = AddressSpace()
    sizes = catalog_sizes(kernel)
    objects = build_objects(machine_layout(kernel), sizes)
    readers, writers = area_readers(sizes), area_writers(sizes)
    counts = notifications if notifications is not None else NotificationCounts()
    for obj in objects:
        service = SERVICE_READERS.get(obj.element)
        read: Getter | None
        if service is not None:
            read = service(counts)
        else:
            read = readers[obj.element](kernel, obj) if obj.access.readable else None
        write = writers[obj.element](kernel, obj) if obj.access.writable else None
        written: Callable[[Any], None] | None = None
        if read is None and write is not None:  # a command: reads give what was written
            echo = LastWritten(obj)
            read, written = echo.read, echo.keep
        space.add(obj, read, write, _aliases(kernel, obj), written)
    # Platform-axis objects (ac_*) are left out: their element names repeat per axis.
    com = [
        o for o in objects if o.port == CncPort.COM and o.group != GroupBase.COM_PLATFORM_AXIS
    ]
    platform = [o for o in com if o.channel == 0]
    directories = {0: platform}
    for k, channel in enumerate(kernel.config.channels, start=1):
        own = [o for o in com if o.channel == channel.id]
        directories[channel.id] = (platform + own) if k == 1 else own
    for channel_id, listed in directories.items():
        directory = ObjectDirectory(listed)
        group = GroupBase.COM_DIRECTORY + channel_id
        index = 0 if channel_id == 0 else kernel.channel_index(channel_id) + 1
        space.add_group(CncPort.COM, group, directory)
        space.add_group(CncPort.COM, index_based(group, channel_id, index), directory)
    return space

