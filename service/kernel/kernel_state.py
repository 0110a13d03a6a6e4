"""The live state the cycle thread works on: ``KernelState`` (channels, drives, axis
parameters, alarms, the channels' runners) and what the kernel sees of a runner
(``ChannelRunnerView``). ``state`` holds the records it is made of and the snapshot."""

from __future__ import annotations

import threading
from dataclasses import dataclass, field
from typing import Protocol

from cnc_objects.protocol.values import RapidOverrideMode

from ..machine_config import ChannelConfig, MachineConfig
from .alarms import AlarmLog
from .axis_params import AxisParameters
from .channel_parts import ChannelSwitches, ErrorEntry, SuspendUnit
from .manual_mode import ManualMode
from .nc.tool_data import ToolingTables
from .plc_functions import PlcFunctions
from .refusal import Refusal
from .state import Channel, CycleStats, LinkState, LogicalAxis, PhysicalAxis, Snapshot


class ChannelRunnerView(Protocol):
    """What the kernel, its commands and the switchover use of a channel's runner
    (``channel_run.ChannelRunner``, which imports this module)."""

    config: ChannelConfig  # the channel's configuration
    touched: bool  # the last cycle changed the channel's state
    # set when a RESET of the channel is queued: a cycle waiting for its decoder stops
    reset_pending: threading.Event
    plc: PlcFunctions  # the channel's M/S/T functions to the PLC and its spindle
    channel: Channel  # the channel's state, as objects show it
    tables: ToolingTables  # the channel's tool list and zero offset table (live)
    manual: ManualMode  # manual mode of the channel's axes

    @property
    def moving(self) -> bool:
        """The path is not at standstill."""

    def select_mode(self, mode: int) -> Refusal | None:
        """Choose the operation mode."""

    def select_program(self, name: str) -> Refusal | None:
        """Select a program of the store."""

    def start(self) -> Refusal | None:
        """START."""

    def hold(self) -> Refusal | None:
        """Feedhold."""

    def reset(self) -> Refusal | None:
        """RESET."""

    def manual_block(self, text: str) -> Refusal | None:
        """Run ``text`` as manual blocks (MDI)."""

    def answer_contour_request(self) -> None:
        """Fill the contour look-ahead's response (the PLC set the semaphore)."""

    def internal_hold(self) -> bool:
        """Brake the path for a suspend request; True when this started it."""

    def release_internal_hold(self) -> bool:
        """End the internal feedhold; True when one was active."""

    def initialise_channel(self) -> None:
        """Channel init (start-up, RESET)."""

    def report(self, error: ErrorEntry) -> None:
        """List ``error``."""

    def cycle(self, time_s: float) -> bool:
        """One GEO cycle; True while the channel has motion or decoding to do."""

    def cruise_budget(self, most: int) -> int | None:
        """Cycles (at most ``most``) that may run in bulk; None: its cycles change nothing."""

    def cruise(self, cycles: int, time_s: float) -> None:
        """Run ``cycles`` cycles that ``cruise_budget`` allowed, the last at ``time_s``."""


@dataclass(slots=True)
class KernelState:
    """The live state the cycle thread works on."""

    channels: list[Channel] = field(default_factory=list)
    physical_axes: list[PhysicalAxis] = field(default_factory=list)
    runners: list[ChannelRunnerView] = field(default_factory=list)  # per channel (kernel sets)
    # by logical axis number
    axis_params: dict[int, AxisParameters] = field(default_factory=dict)
    alarms: AlarmLog = field(default_factory=AlarmLog)  # the kernel's (kernel sets)

    @classmethod
    def from_config(cls, config: MachineConfig) -> KernelState:
        """Initial state: every channel links its axes unless its output is suspended."""
        state = cls(
            channels=[_channel_from_config(c, config) for c in config.channels],
            physical_axes=[PhysicalAxis(a.number, a.name) for a in config.physical_axes],
        )
        by_number = state.drive_by_number()
        for channel in state.channels:
            if channel.suspend.output_suspended:
                continue
            for axis in channel.axes:
                drive = by_number[axis.requested_link]
                if drive.linked_logical_axis == 0:
                    drive.linked_logical_axis = drive.last_logical_axis = axis.logical_number
                    axis.actual_link = drive.number
                    axis.link_state = LinkState.LINKED
                else:  # another channel holds it: the request waits for it
                    axis.link_state = LinkState.WAITING_ACK
        return state

    def drive_by_number(self) -> dict[int, PhysicalAxis]:
        """The physical axes by number."""
        return {p.number: p for p in self.physical_axes}

    def drive_axes(self) -> None:
        """Position controller: each physical axis follows the increments of the logical
        axis linked to it (ideal drive: actual position = command position). A logical
        axis without a link keeps its output where it was: no step is lost or invented
        when it links again."""
        drives = self.physical_axes
        for channel in self.channels:
            for axis in channel.axes:
                delta = axis.command_position_01um - axis.output_01um
                if not delta or not axis.actual_link:
                    continue
                for drive in drives:
                    if drive.number == axis.actual_link:
                        drive.command_position_01um += delta
                        drive.actual_position_01um = drive.command_position_01um
                        break
                axis.output_01um = axis.command_position_01um

    def snapshot(
        self,
        cycle: int,
        time_ns: int,
        wall_ns: int,
        stats: CycleStats,
        previous: Snapshot | None = None,
        changed: list[bool] | None = None,
        drives_changed: bool = True,
    ) -> Snapshot:
        """Frozen copies of everything readable.

        With ``previous`` and ``changed`` (one flag per channel), a channel that did not
        change this cycle keeps its frozen copy from ``previous``: an idle channel costs
        nothing per cycle. Without them every channel is copied; the physical axes are
        copied unless ``drives_changed`` is False (with ``previous``). ``time_ns`` and
        ``wall_ns``: kernel time and wall-clock time of the cycle (see ``Snapshot``).
        """
        if previous is None or changed is None:
            channels = tuple(c.frozen() for c in self.channels)
        elif not any(changed):
            channels = previous.channels
        else:
            channels = tuple(
                c.frozen() if touched else old
                for c, touched, old in zip(self.channels, changed, previous.channels, strict=True)
            )
        drives = (previous.physical_axes if previous is not None and not drives_changed
                  else tuple(p.frozen() for p in self.physical_axes))
        return Snapshot(cycle, time_ns, wall_ns, stats.frozen(), channels, drives)


def _channel_from_config(config: ChannelConfig, machine: MachineConfig) -> Channel:
    suspended = config.suspend_output_at_start
    axes = [
        LogicalAxis(
            a.name,
            a.logical_number,
            machine.link_of(a.logical_number),
            link_state=LinkState.REQUESTED if suspended else LinkState.LINKED,
        )
        for a in config.axes
    ]
    override = min(1000, config.feed_override_max)
    switches = ChannelSwitches(
        feed_override_max=config.feed_override_max, feed_override_command=override,
        feed_override_per_mille=override, syn_chk=config.syn_chk,
        g00_override_mode=RapidOverrideMode[config.g00_override_mode],
    )
    suspend = SuspendUnit(command_w=suspended, request_r=suspended, output_suspended=suspended)
    return Channel(config.id, config.name, axes, switches, suspend)
