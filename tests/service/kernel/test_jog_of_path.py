"""Jog of path (FCT-C15) in the kernel: switchover handshake, suspension, offsets, clones.

The real kernel on the virtual clock; every check reads the published snapshots.
"""

from __future__ import annotations

from typing import Any

import pytest

from cnc_objects.service.config import build_config
from cnc_objects.service.kernel.axis_params import AxisErrorId
from cnc_objects.service.kernel.channel_mode import ChannelState
from cnc_objects.service.kernel.commands import (
    ManualBlock,
    RefusalReason,
    ResetChannel,
    SetExecutionMode,
    SetSuspendCommand,
    SetSuspendEnable,
    UpdateAxisParameters,
)
from cnc_objects.service.kernel.state import LinkState, Snapshot
from tests.support.kernel import KernelHarness

EXTENDED_MDI = 0x80
INCR = 10_000  # 0.1 um per mm


class Machine:
    """Two channels sharing drive X through axes 1 (channel 1) and 11 (channel 2)."""

    def __init__(self, harness: KernelHarness) -> None:
        self.h = harness
        self.done = [0, 0]  # manual blocks finished per channel

    def snap(self) -> Snapshot:
        return self.h.kernel.snapshot

    def suspend(self, ci: int, on: bool) -> None:
        assert self.h.command(SetSuspendCommand(ci, on)) is None
        self.h.wait_for(lambda s: s.channels[ci].suspend.output_suspended == on)

    def linked(self, ci: int) -> Snapshot:
        return self.h.wait_for(
            lambda s: all(a.link_state == LinkState.LINKED for a in s.channels[ci].axes)
        )

    def mdi(self, ci: int, text: str) -> Snapshot:
        assert self.h.command(ManualBlock(ci, text)) is None
        self.done[ci] += 1
        want = self.done[ci]
        return self.h.wait_for(
            lambda s: s.channels[ci].block.manual_blocks_done >= want
            and s.channels[ci].path.path_velocity_mm_s == 0.0
            or s.channels[ci].state == ChannelState.ERROR
        )

    def row(self) -> tuple[float, float, float, float, float]:
        """(ch1 command X, ch2 command X, physical X, offset ch1, offset ch2) in mm."""
        s = self.snap()
        x1, x2 = s.channels[0].axes[0], s.channels[1].axes[0]
        drive = s.physical_axes[0]
        return (
            x1.command_position_01um / INCR, x2.command_position_01um / INCR,
            drive.command_position_01um / INCR,
            x1.position_offset_01um / INCR, x2.position_offset_01um / INCR,
        )


@pytest.fixture
def machine() -> Any:
    with KernelHarness() as harness:
        m = Machine(harness)
        for ci in (0, 1):
            assert harness.command(SetExecutionMode(ci, EXTENDED_MDI)) is None
        yield m


def switch_to(m: Machine, ci: int) -> None:
    """Suspend the other channel, resume channel ``ci`` and wait for its links."""
    m.suspend(1 - ci, True)
    m.suspend(ci, False)
    m.linked(ci)


def test_the_function_description_table_step_by_step(machine: Machine) -> None:
    m = machine
    assert m.snap().channels[1].suspend.output_suspended  # channel 2 starts suspended
    m.mdi(0, "G01 G90 X50 F6000")
    assert m.row() == (50, 0, 50, 0, 0)
    switch_to(m, 1)
    m.mdi(1, "G01 G90 X15 F6000")
    assert m.row() == (50, 15, 15, 0, 0)  # channel 1 has not taken the axis back: 0
    switch_to(m, 0)
    m.mdi(0, "X80")
    assert m.row() == (80, 15, 45, 35, -30)
    switch_to(m, 1)
    m.mdi(1, "X0")
    assert m.row() == (80, 0, 30, 50, -30)
    # The PLC side shows the offset of the link that drives the physical axis.
    s = m.snap()
    assert s.physical_axes[0].linked_logical_axis == 11
    assert s.physical_axes[0].position_offset_01um == -30 * INCR


def test_a_second_sequence_with_three_handovers(machine: Machine) -> None:
    """Own sequence: incremental blocks, Y too, and a RESET (channel init) at the end."""
    m = machine
    m.mdi(0, "G01 G90 X10 Y20 F6000")
    switch_to(m, 1)
    m.mdi(1, "G01 G91 Y10 F6000")  # 20 -> 30 on the drive, as the example of section 2.4
    s = m.snap()
    assert s.physical_axes[1].command_position_01um == 30 * INCR
    assert s.channels[1].axes[1].command_position_01um == 30 * INCR
    assert s.channels[0].axes[1].position_offset_01um == 0  # not taken back yet
    switch_to(m, 0)
    m.mdi(0, "G91 Y-5 X5")  # channel 1 continues from its own 20: drive Y 30 -> 25
    s = m.snap()
    ch1_y, ch2_y = s.channels[0].axes[1], s.channels[1].axes[1]
    assert s.physical_axes[1].command_position_01um == 25 * INCR
    assert ch1_y.command_position_01um == 15 * INCR
    assert ch1_y.position_offset_01um == -10 * INCR  # 15 - 25
    assert ch2_y.position_offset_01um == 5 * INCR  # 30 - 25
    assert s.channels[0].axes[0].position_offset_01um == 0  # X: 15 on both
    # RESET is channel init: command positions take the drives', offsets cleared.
    assert m.h.command(ResetChannel(0, True)) is None
    s = m.h.wait_for(lambda s: s.channels[0].state != ChannelState.ACTIVE)
    assert s.channels[0].axes[1].command_position_01um == 25 * INCR
    assert s.channels[0].axes[1].position_offset_01um == 0


def test_handshake_states_in_order_cycle_by_cycle(machine: Machine) -> None:
    m = machine
    seen: list[tuple[int, int, int]] = []  # (cycle, link_state, actual link) on change

    def watch(s: Snapshot) -> bool:
        ax = s.channels[1].axes[0]
        if not seen or seen[-1][1:] != (ax.link_state, ax.actual_link):
            seen.append((s.cycle, ax.link_state, ax.actual_link))
        return ax.link_state == LinkState.LINKED

    m.suspend(0, True)
    linked = m.h.watch(watch)
    assert m.h.command(SetSuspendCommand(1, False)) is None
    assert linked.wait(10)
    first = seen[0][0]
    assert seen == [
        (first, LinkState.REQUESTED, 0),  # output resumed: the axis is requested
        (first + 1, LinkState.WAITING_ACK, 0),  # the position controller has the request
        (first + 2, LinkState.LINKED, 1),  # acknowledged: the link exists
    ]


def test_request_waits_while_the_other_channel_holds_the_axis(machine: Machine) -> None:
    m = machine
    assert m.h.command(SetSuspendCommand(1, False)) is None
    s = m.h.wait_for(lambda s: s.channels[1].axes[0].link_state == LinkState.WAITING_ACK)
    start_cycle = s.cycle
    # Channel 1 keeps the drive; channel 2 waits, however long.
    m.mdi(0, "G01 G90 X5 F6000")
    s = m.snap()
    assert s.cycle > start_cycle + 10
    assert [a.link_state for a in s.channels[1].axes] == [LinkState.WAITING_ACK] * 3
    assert s.physical_axes[0].linked_logical_axis == 1
    # A manual block in channel 2 waits for the axes and does not move anything.
    assert m.h.command(ManualBlock(1, "G01 G90 X1 F6000")) is None
    s = m.snap()
    assert s.channels[1].state == ChannelState.ACTIVE
    assert s.physical_axes[0].command_position_01um == 5 * INCR
    m.suspend(0, True)
    s = m.linked(1)
    m.done[1] += 1
    s = m.h.wait_for(lambda s: s.channels[1].block.manual_blocks_done >= 1
                     and s.channels[1].path.path_velocity_mm_s == 0)
    assert s.channels[1].axes[0].command_position_01um == 1 * INCR  # started at 5 (adjusted)
    assert s.physical_axes[0].command_position_01um == 1 * INCR


def test_suspending_a_moving_channel_brakes_it_first_then_it_continues(machine: Machine) -> None:
    m = machine
    h = m.h
    assert h.command(ManualBlock(0, "G01 G90 X200 F30000")) is None
    h.wait_for(lambda s: s.channels[0].path.path_velocity_mm_s > 100)
    assert h.command(SetSuspendCommand(0, True)) is None
    s = h.wait_for(lambda s: s.channels[0].suspend.output_suspended)
    ch = s.channels[0]
    assert ch.path.path_velocity_mm_s == 0.0 and ch.state == ChannelState.ACTIVE
    stopped_at = ch.axes[0].command_position_01um
    assert 0 < stopped_at < 200 * INCR
    assert s.physical_axes[0].linked_logical_axis == 0
    m.suspend(0, False)
    m.linked(0)
    s = h.wait_for(lambda s: s.channels[0].block.manual_blocks_done >= 1
                   and s.channels[0].path.path_velocity_mm_s == 0)
    assert s.channels[0].axes[0].command_position_01um == 200 * INCR
    assert s.physical_axes[0].command_position_01um == 200 * INCR


def test_suspending_is_refused_in_error_state_and_works_after_reset(machine: Machine) -> None:
    m = machine
    m.mdi(0, "G01 X1 F6000 Q7")  # unknown word: channel 1 goes to ERROR
    assert m.snap().channels[0].state == ChannelState.ERROR
    refusal = m.h.command(SetSuspendCommand(0, True))
    assert refusal is not None and refusal.reason == RefusalReason.NOT_READY
    assert "in error" in refusal.message and "RESET" in refusal.message
    assert not m.snap().channels[0].suspend.command_w
    assert not m.snap().channels[0].suspend.output_suspended
    assert m.h.command(ResetChannel(0, True)) is None
    m.suspend(0, True)
    assert m.snap().physical_axes[0].linked_logical_axis == 0


def test_enable_false_hands_the_unit_to_the_cnc_request(machine: Machine) -> None:
    m = machine
    # Channel 2: command_w TRUE (suspended); with enable FALSE the CNC's own request
    # (suspend_output_at_start = TRUE) applies, so it stays suspended.
    assert m.h.command(SetSuspendEnable(1, False)) is None
    assert m.h.command(SetSuspendCommand(1, False)) is None
    s = m.snap()
    assert s.channels[1].suspend.output_suspended and s.channels[1].suspend.request_r
    assert m.h.command(SetSuspendEnable(1, True)) is None
    m.h.wait_for(lambda s: not s.channels[1].suspend.output_suspended)


# ------------------------------------------------------------------ configuration


def _config(**jog_channel: Any) -> Any:
    base = build_config().model_dump(exclude_unset=True)
    main, jog = base["channels"]
    main["axes"][0]["limits"] = {"vel_max_mm_s": 300.0, "acc_max_mm_s2": 2000.0}
    jog.update(jog_channel)
    return build_config({"channels": [main, jog]})


def test_clone_takes_the_master_parameters_and_overrides_what_it_lists() -> None:
    config = _config(axes=[
        {"name": "X", "logical_number": 11, "link_to": 1, "clone_of": 1},
        {"name": "Y", "logical_number": 12, "clone_of": 2,
         "limits": {"acc_max_mm_s2": 1234.0}},
        {"name": "Z", "logical_number": 13, "link_to": 3, "clone_of": 3},
    ])
    with KernelHarness(config=config) as h:
        p = h.kernel.axis_params
        assert (p[11].vel_max_mm_s, p[11].acc_max_mm_s2, p[11].cloned) == (300.0, 2000.0, True)
        assert p[12].acc_max_mm_s2 == 1234.0 and p[12].vel_max_mm_s == p[2].vel_max_mm_s
        assert p[12].link_to == 2  # inherited from the master
        assert h.kernel.snapshot.channels[1].errors.entries == ()
        # A later change of the master does not reach the clone.
        assert h.command(UpdateAxisParameters({"logical_number": 1,
                                               "limits": {"vel_max_mm_s": 100.0}})) is None
        assert h.kernel.axis_params[1].vel_max_mm_s == 100.0
        assert h.kernel.axis_params[11].vel_max_mm_s == 300.0
        # The clone reference cannot change after the first initialisation.
        refusal = h.command(UpdateAxisParameters({"logical_number": 11, "clone_of": 2}))
        assert refusal is not None and "cannot change" in refusal.message
        assert h.kernel.axis_params[11].clone_of == 1


def test_clone_of_a_missing_master_reports_70172_and_50462_and_is_uncloned() -> None:
    config = _config(jog_of_path_only=False, axes=[
        {"name": "X", "logical_number": 11, "link_to": 1, "clone_of": 99},
        {"name": "Y", "logical_number": 12, "link_to": 2, "clone_of": 2},
        {"name": "Z", "logical_number": 13, "link_to": 3, "clone_of": 3},
    ])
    with KernelHarness(config=config) as h:
        ch2 = h.kernel.snapshot.channels[1]
        assert [e.id for e in ch2.errors.entries] == [70172, 50462]
        assert all(e.warning for e in ch2.errors.entries) and "99" in ch2.errors.entries[0].text
        assert ch2.state != ChannelState.ERROR  # warnings: the channel works
        assert not h.kernel.axis_params[11].cloned
        assert h.kernel.axis_params[11].vel_max_mm_s == 500.0  # its own (default) value


def test_jog_of_path_only_channel_with_a_non_clone_axis_is_in_error() -> None:
    config = _config(axes=[
        {"name": "X", "logical_number": 11, "link_to": 1, "clone_of": 1},
        {"name": "Y", "logical_number": 12, "link_to": 2},
        {"name": "Z", "logical_number": 13, "link_to": 3, "clone_of": 3},
    ])
    with KernelHarness(config=config) as h:
        ch2 = h.kernel.snapshot.channels[1]
        assert ch2.state == ChannelState.ERROR
        assert ch2.errors.entries[0].id == AxisErrorId.JOG_OF_PATH_AXIS_NOT_CLONE
        assert "axis Y" in ch2.errors.entries[0].text and "12" in ch2.errors.entries[0].text
        # Checked again at RESET: the error comes back.
        assert h.command(ResetChannel(1, True)) is None
        ch2 = h.kernel.snapshot.channels[1]
        assert ch2.state == ChannelState.ERROR and ch2.errors.entries[0].id == 70900


# ------------------------------------------------------------------ axis release


def _release_y_then_switch(config: Any) -> Snapshot:
    """Channel 1 releases Y (#AX RELEASE) and suspends; channel 2 resumes."""
    with KernelHarness(config=config) as h:
        m = Machine(h)
        assert h.command(SetExecutionMode(0, EXTENDED_MDI)) is None
        m.mdi(0, "G01 G90 X10 Y10 F6000")
        m.mdi(0, "#AX RELEASE [Y]")
        assert h.kernel.snapshot.channels[0].axes[1].released
        m.mdi(0, "X20")  # the channel goes on without Y
        m.suspend(0, True)
        assert h.command(SetSuspendCommand(1, False)) is None
        # X and Z link; Y is linked or waits, depending on auto_release_of_axis_link.
        return h.wait_for(lambda s: s.channels[1].axes[0].link_state == LinkState.LINKED
                          and s.channels[1].axes[2].link_state == LinkState.LINKED
                          and s.channels[1].axes[1].link_state != LinkState.REQUESTED)


def test_released_axis_keeps_its_drive_without_auto_release() -> None:
    s = _release_y_then_switch(build_config())
    assert s.channels[1].axes[1].link_state == LinkState.WAITING_ACK
    assert s.physical_axes[1].linked_logical_axis == 2  # still the released axis 2
    assert s.channels[0].axes[1].actual_link == 2


def test_auto_release_of_axis_link_frees_the_drive_at_the_release() -> None:
    base = build_config().model_dump(exclude_unset=True)
    base["channels"][0]["axes"][1]["auto_release_of_axis_link"] = True
    s = _release_y_then_switch(build_config({"channels": base["channels"]}))
    assert s.channels[1].axes[1].link_state == LinkState.LINKED
    assert s.physical_axes[1].linked_logical_axis == 12
    assert s.channels[0].axes[1].actual_link == 0


def test_program_start_brings_released_axes_back() -> None:
    base = build_config().model_dump(exclude_unset=True)
    base["channels"][0]["axes"][1]["auto_release_of_axis_link"] = True
    with KernelHarness(config=build_config({"channels": base["channels"]})) as h:
        run = h.run("#AX RELEASE [Y]\nG01 X5 F6000\nM30\n")
        assert run.channel.axes[1].released and run.channel.axes[1].actual_link == 0
        run = h.run("G01 X1 Y7 F6000\nM30\n", name="again.nc")
        assert run.channel.state == ChannelState.READY
        assert not run.channel.axes[1].released and run.channel.axes[1].actual_link == 2
        assert run.final.physical_axes[1].command_position_01um == 7 * INCR
