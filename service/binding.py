"""Binds the catalog to the kernel: a getter on the snapshot and a command per object.

This is the one place that knows both an object's element name and where the kernel
keeps its value. Reads come from ``kernel.snapshot`` (the last published cycle); writes
become kernel commands, applied by the cycle thread before the reply is sent.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from objects import AddressSpace, ChannelLayout, CncObject, MachineLayout, build_objects
from objects.addressing import LOGICAL_BIT, GroupBase, index_based
from objects.directory import ObjectDirectory
from protocol.constants import CncPort
from protocol.errors import AdsReturnCode

from . import __version__
from .kernel.commands import Command, Refusal, RefusalReason, SetExecutionMode, SetFeedOverride
from .kernel.kernel import Kernel

Getter = Callable[[], Any]
CommandFactory = Callable[[Any], Command]

REFUSAL_CODES: dict[RefusalReason, AdsReturnCode] = {
    RefusalReason.INVALID_VALUE: AdsReturnCode.DEVICE_INVALIDDATA,
    RefusalReason.NOT_READY: AdsReturnCode.DEVICE_NOTREADY,
    RefusalReason.BUSY: AdsReturnCode.DEVICE_BUSY,
}


def refusal_code(refusal: Refusal) -> AdsReturnCode:
    """The ADS code that answers a kernel refusal."""
    return REFUSAL_CODES[refusal.reason]


def _channel(attr: str) -> Callable[[Kernel, CncObject], Getter]:
    def bind(kernel: Kernel, obj: CncObject) -> Getter:
        ci = kernel.channel_index(obj.channel)
        return lambda: getattr(kernel.snapshot.channels[ci], attr)

    return bind


def _channel_axis(attr: str) -> Callable[[Kernel, CncObject], Getter]:
    def bind(kernel: Kernel, obj: CncObject) -> Getter:
        ci, ai = kernel.channel_index(obj.channel), obj.axis - 1
        return lambda: getattr(kernel.snapshot.channels[ci].axes[ai], attr)

    return bind


def _physical_axis(attr: str) -> Callable[[Kernel, CncObject], Getter]:
    def bind(kernel: Kernel, obj: CncObject) -> Getter:
        index = [p.number for p in kernel.state.physical_axes].index(obj.axis)
        return lambda: getattr(kernel.snapshot.physical_axes[index], attr)

    return bind


def _stats(attr: str, wrap: Callable[[Any], Any] = lambda v: v) -> Callable[..., Getter]:
    def bind(kernel: Kernel, obj: CncObject) -> Getter:
        return lambda: wrap(getattr(kernel.snapshot.stats, attr))

    return bind


def _constant(value: Callable[[Kernel], Any]) -> Callable[[Kernel, CncObject], Getter]:
    def bind(kernel: Kernel, obj: CncObject) -> Getter:
        fixed = value(kernel)
        return lambda: fixed

    return bind


def _kernel_time(kernel: Kernel, obj: CncObject) -> Getter:
    return lambda: kernel.snapshot.time_ns / 1e9


READERS: dict[str, Callable[[Kernel, CncObject], Getter]] = {
    "requested_link_to_physical_axis": _channel_axis("requested_link"),
    "actual_link_to_physical_axis": _channel_axis("actual_link"),
    "link_state": _channel_axis("link_state"),
    "dist_prog_start": _channel("dist_prog_start_incr"),
    "mc_command_feed_override_r": _channel("feed_override_command"),
    "mc_active_feed_override_r": _channel("feed_override_active"),
    "mc_command_execution_mode_r": _channel("execution_mode_command"),
    "mc_active_execution_mode_r": _channel("execution_mode_active"),
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
    "command_position_acs": _physical_axis("command_position_incr"),
    "actual_position_acs": _physical_axis("actual_position_incr"),
    "link_to_logical_axis": _physical_axis("linked_logical_axis"),
}


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
}


def machine_layout(kernel: Kernel) -> MachineLayout:
    """The layout the catalog is expanded over, from the kernel's configuration."""
    return MachineLayout(
        channels=tuple(ChannelLayout(c.id, len(c.axes)) for c in kernel.config.channels),
        physical_axes=tuple(a.number for a in kernel.config.physical_axes),
    )


def _aliases(kernel: Kernel, obj: CncObject) -> list[int]:
    """Other groups that address ``obj``: the index-based spelling, platform under ch 1."""
    if obj.channel:
        return [index_based(obj.group, obj.channel, kernel.channel_index(obj.channel) + 1)]
    aliases = [obj.group & ~LOGICAL_BIT]
    if obj.group == GroupBase.COM_CHANNEL:  # platform data may be addressed as channel 1
        first = GroupBase.COM_CHANNEL + 1
        aliases += [first, first & ~LOGICAL_BIT]
    return aliases


def build_address_space(kernel: Kernel) -> AddressSpace:
    """Every catalog object bound to ``kernel``, plus the COM object directories."""
    space = AddressSpace()
    objects = build_objects(machine_layout(kernel))
    for obj in objects:
        read = READERS[obj.element](kernel, obj) if obj.access.readable else None
        write = WRITERS[obj.element](kernel, obj) if obj.access.writable else None
        space.add(obj, read, write, _aliases(kernel, obj))
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

