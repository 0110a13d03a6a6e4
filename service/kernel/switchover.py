"""Jog of path (FCT-C15): channels hand physical axes to each other, cycle by cycle.

A physical axis is driven by one logical axis at a time. Each cycle, before the
channels move:

1. the link handshake advances: a logical axis that requested its physical axis last
   cycle (``link_state`` 1) now waits for the acknowledgement (2); one that waits is
   acknowledged as soon as no other logical axis holds the physical axis, and the link
   exists (0). A channel moves only while all its axes are linked;
2. each channel's ``suspend_axis_output`` unit is evaluated. Suspending waits for the
   axes to stand (the channel runner brakes them with an internal feedhold) and then
   gives the physical axes up; it is not done while the channel is in error. Resuming
   requests the axes again (``link_state`` 1).

After the drives have followed their axes, ``update_offsets`` computes the position
offsets (command position of the channel axis - position of the physical axis). The
rule, worked out from the FCT-C15 example and written down in docs/jog-of-path.md: a
logical axis has an offset while it is linked, and, once it has taken its physical axis
over from another logical axis, also while it is not; before that (and after channel
init) it reads 0.
"""

from __future__ import annotations

from dataclasses import replace

from .axis_params import AxisParameters
from .channel_mode import ChannelState
from .kernel_state import KernelState
from .state import Channel, LinkState, LogicalAxis, PhysicalAxis


class Switchover:
    """The link handshake and the suspend units of all channels of one kernel state."""

    def __init__(self, state: KernelState, params: dict[int, AxisParameters]) -> None:
        self._state = state
        self._params = params
        self._drives = state.drive_by_number()
        # (channel index, axis, its drive) for every logical axis: the cycle walks this.
        self._axes: list[tuple[int, LogicalAxis, PhysicalAxis]] = [
            (ci, axis, self._drives[axis.requested_link])
            for ci, channel in enumerate(state.channels)
            for axis in channel.axes
        ]
        self.in_progress = False  # a handshake will advance without outside help

    # ------------------------------------------------------------ links

    def step(self, changed: list[bool]) -> None:
        """Advance every handshake and suspend unit by one cycle; sets ``changed[ci]``
        for each channel whose state this changed."""
        channels = self._state.channels
        progress = False
        for ci, axis, drive in self._axes:
            if axis.actual_link:
                if axis.released and self._auto_release(axis):
                    self._unlink(axis, drive)
                    changed[ci] = True
                continue
            if channels[ci].suspend.output_suspended or axis.released:
                continue
            if axis.link_state == LinkState.REQUESTED:
                axis.link_state = LinkState.WAITING_ACK  # the position controller has it
                changed[ci] = True
                progress = True
            elif drive.linked_logical_axis == 0:
                self._link(axis, drive)
                changed[ci] = True
        for ci, channel in enumerate(channels):
            if self._suspend_unit(ci, channel):
                changed[ci] = True
                progress = True
        self.in_progress = progress

    def at_rest(self) -> bool:
        """``step`` would change nothing: every channel's output is as commanded
        (suspended or not) and every axis of a channel whose output runs is linked and
        not released (the event-speed virtual clock runs cycles in bulk only then)."""
        if self.in_progress:
            return False
        channels = self._state.channels
        for channel in channels:
            if channel.suspend.commanded != channel.suspend.output_suspended:
                return False
        for ci, axis, _drive in self._axes:
            if axis.released or not (axis.actual_link or channels[ci].suspend.output_suspended):
                return False
        return True

    def _auto_release(self, axis: LogicalAxis) -> bool:
        params = self._params.get(axis.logical_number)
        return params is not None and params.auto_release_of_axis_link

    @staticmethod
    def _link(axis: LogicalAxis, drive: PhysicalAxis) -> None:
        """Acknowledge the request: the axis drives ``drive`` from now on, from where it
        stands (no step is handed over)."""
        if drive.last_logical_axis not in (0, axis.logical_number):
            axis.offset_live = True  # taken over from another logical axis
        drive.linked_logical_axis = drive.last_logical_axis = axis.logical_number
        axis.actual_link = drive.number
        axis.link_state = LinkState.LINKED
        axis.output_01um = axis.command_position_01um

    @staticmethod
    def _unlink(axis: LogicalAxis, drive: PhysicalAxis) -> None:
        if drive.linked_logical_axis == axis.logical_number:
            drive.linked_logical_axis = 0
        axis.actual_link = 0
        axis.link_state = LinkState.REQUESTED

    def _suspend_unit(self, ci: int, channel: Channel) -> bool:
        """Apply the unit's command to the channel; True when something changed."""
        runner = self._state.runners[ci]
        if channel.suspend.commanded:
            if channel.suspend.output_suspended or channel.state == ChannelState.ERROR:
                return False
            if runner.moving:
                return runner.internal_hold()
            for axis in channel.axes:
                if axis.actual_link and not axis.released:  # a released axis keeps its
                    self._unlink(axis, self._drives[axis.actual_link])  # link (P-AXIS-00483)
            channel.suspend = replace(channel.suspend, output_suspended=True)
            return True
        changed = runner.release_internal_hold()
        if channel.suspend.output_suspended:
            channel.suspend = replace(channel.suspend, output_suspended=False)
            for axis in channel.axes:
                if not axis.actual_link:
                    axis.link_state = LinkState.REQUESTED
            return True
        return changed

    # ------------------------------------------------------------ offsets

    def update_offsets(self, changed: list[bool]) -> None:
        """Position offset of every logical axis and of every physical axis's link."""
        for ci, axis, drive in self._axes:
            if axis.actual_link or axis.offset_live:
                offset = axis.command_position_01um - drive.command_position_01um
            else:
                offset = 0
            if offset != axis.position_offset_01um:
                axis.position_offset_01um = offset
                changed[ci] = True
            if drive.linked_logical_axis == axis.logical_number:
                drive.position_offset_01um = offset
        for drive in self._state.physical_axes:
            if not drive.linked_logical_axis:
                drive.position_offset_01um = 0

    def adjust_to_drives(self, channel: Channel) -> None:
        """Position adjustment: the channel's command positions take the positions of
        the physical axes (program start, channel init); the offsets become 0."""
        for axis in channel.axes:
            axis.set_position_01um(self._drives[axis.requested_link].command_position_01um)
            axis.position_offset_01um = 0
