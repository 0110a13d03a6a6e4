"""Manual mode and homing in the real kernel, cycle by cycle (virtual clock).

Every function is driven through the commands the objects' writes become (as an HMI or
PLC would), and every figure is read from the published snapshots: positions of the
channel axis and of its drive, the manual views, the channel's state and errors.
"""

from __future__ import annotations

from typing import Any

import pytest

from cnc_objects.protocol.values import ChannelMode, ChannelState, ManualOperationMode
from cnc_objects.service.kernel.alarms import AlarmClass, Severity
from cnc_objects.service.kernel.commands import (
    Feedhold,
    RefusalReason,
    ResetChannel,
    SelectMode,
    SelectProgram,
    SetSuspendCommand,
    StartProgram,
)
from cnc_objects.service.kernel.commands_manual import ManualAxisCommand
from cnc_objects.service.kernel.manual_mode import ManualErrorId
from tests.support.kernel import KernelHarness
from tests.support.manual_machine import (
    ACC_MM_S2,
    HOMING_MM_S,
    JOG_MM_S,
    LIMIT_MAX_MM,
    LIMIT_MIN_MM,
    REF_MM,
    machine,
)

CYCLE_S = 0.001




@pytest.fixture
def k():
    with KernelHarness(config=machine()) as harness:
        yield harness


def write(k: KernelHarness, action: str, value: int | bool, axis: int = 0):
    return k.command(ManualAxisCommand(0, axis, action, value))


def manual(k: KernelHarness) -> None:
    assert k.command(SelectMode(0, ChannelMode.MANUAL)) is None


def x_01um(k: KernelHarness) -> int:
    return k.kernel.snapshot.channels[0].axes[0].command_position_01um


def view(k: KernelHarness, axis: int = 0):
    return k.kernel.snapshot.channels[0].manual[axis]


def record_until_rest(k: KernelHarness, *writes: tuple[str, int | bool], axis: int = 0,
                      then: tuple[Any, Any] | None = None,
                      ) -> list[tuple[float, float]]:
    """Apply ``writes`` (action, value) to the axis and record (position mm, velocity
    mm/s) in every cycle from before the first write until the axis's motion is over.
    ``then`` = (predicate on the axis's view, command): the write an HMI makes at the
    cycle the predicate first holds (submitted from the cycle thread, so it is
    applied in the next cycle whatever the speed of the virtual clock)."""
    samples: list[tuple[float, float]] = []
    armed = [False]
    pending = [then]

    def sample(snap) -> bool:
        ch = snap.channels[0]
        samples.append((ch.axes[axis].position_mm, ch.manual[axis].velocity_um_s / 1000))
        trigger = pending[0]
        if trigger is not None and trigger[0](ch.manual[axis]):
            pending[0] = None
            k.kernel.submit(trigger[1], lambda refusal: None)
            return False
        return armed[0] and pending[0] is None and not ch.manual[axis].moving

    event = k.watch(sample)
    for action, value in writes:
        assert write(k, action, value, axis) is None, (action, value)
    armed[0] = True
    if not k.kernel.snapshot.channels[0].manual[axis].moving:
        event.set()
    assert event.wait(30), "the manual motion did not end in time"
    k._condition = None
    return samples


def assert_ramps(samples: list[tuple[float, float]], acc_mm_s2: float) -> None:
    """Velocity changes by at most acc * dt per cycle (the samples begin before the
    motion, or while it runs)."""
    velocities = [v for _, v in samples]
    for a, b in zip(velocities, velocities[1:], strict=False):
        assert abs(b - a) <= acc_mm_s2 * CYCLE_S * (1 + 1e-6) + 1e-9, (a, b)


def test_incremental_jog_from_0_1_um_to_10_mm_and_refuses_outside(k) -> None:
    manual(k)
    assert write(k, "operation_mode", ManualOperationMode.INCREMENTAL) is None
    assert write(k, "increment", 1) is None  # 0.1 um
    record_until_rest(k, ("jog_plus", True))
    assert x_01um(k) == 1
    assert write(k, "jog_plus", False) is None
    assert write(k, "increment", 50_000) is None  # 5 mm
    samples = record_until_rest(k, ("jog_minus", True))
    assert abs(samples[0][1]) <= ACC_MM_S2 * CYCLE_S  # from standstill
    assert x_01um(k) == 1 - 50_000
    assert_ramps(samples, ACC_MM_S2)
    assert max(abs(v) for _, v in samples) <= JOG_MM_S + 1e-9
    drive = k.kernel.snapshot.physical_axes[0]
    assert drive.actual_position_01um == x_01um(k)  # the drive followed
    for bad in (0, 100_001):
        refusal = write(k, "increment", bad)
        assert refusal is not None and refusal.reason == RefusalReason.INVALID_VALUE
        assert "0.1 um .. 10 mm" in refusal.message
    assert view(k).increment_01um == 50_000
    assert k.kernel.snapshot.channels[0].state == ChannelState.READY  # manual mode done


def test_continuous_jog_ramps_to_jog_speed_and_brakes_when_released(k) -> None:
    manual(k)
    write(k, "operation_mode", ManualOperationMode.CONTINUOUS)
    at_speed = (lambda v: v.velocity_um_s >= JOG_MM_S * 1000,
                ManualAxisCommand(0, 0, "jog_plus", False))
    samples = record_until_rest(k, ("jog_plus", True), then=at_speed)
    assert_ramps(samples, ACC_MM_S2)
    top = max(range(len(samples)), key=lambda n: samples[n][1])
    assert samples[top][1] == pytest.approx(JOG_MM_S)
    braking_mm = JOG_MM_S ** 2 / (2 * ACC_MM_S2)  # 0.4 mm
    stopped_mm = samples[-1][0]
    assert stopped_mm < LIMIT_MAX_MM and not view(k).limit_warning
    assert stopped_mm - samples[top][0] == pytest.approx(braking_mm, abs=JOG_MM_S * CYCLE_S)
    assert view(k).tipp_geschw_um_s == JOG_MM_S * 1000


def test_rapid_key_jogs_at_the_rapid_speed(k) -> None:
    manual(k)  # Y: default limits and acceleration, default jog speeds 20 / 100 mm/s
    write(k, "operation_mode", ManualOperationMode.CONTINUOUS, axis=1)
    write(k, "rapid", True, axis=1)
    assert view(k, 1).tipp_geschw_um_s == 100_000
    at_speed = (lambda v: v.velocity_um_s <= -100_000,
                ManualAxisCommand(0, 1, "jog_minus", False))
    samples = record_until_rest(k, ("jog_minus", True), axis=1, then=at_speed)
    assert min(v for _, v in samples) == pytest.approx(-100.0)
    assert_ramps(samples, 5000.0)


def test_continuous_jog_stops_exactly_at_the_software_limit_with_a_warning(k) -> None:
    manual(k)
    write(k, "operation_mode", ManualOperationMode.CONTINUOUS)
    samples = record_until_rest(k, ("jog_plus", True))
    assert_ramps(samples, ACC_MM_S2)
    assert x_01um(k) == LIMIT_MAX_MM * 10_000
    assert max(p for p, _ in samples) <= LIMIT_MAX_MM
    assert view(k).limit_warning
    ch = k.kernel.snapshot.channels[0]
    assert ch.state == ChannelState.READY  # a warning, not an error
    [warning] = [e for e in ch.errors.entries if e.id == ManualErrorId.SW_LIMIT_REACHED]
    assert warning.warning and "software limit" in warning.text
    # ... and an alarm of the axes, a warning (docs/alarms.md)
    [alarm] = [a for a in k.kernel.alarms.view.active if a.id == ManualErrorId.SW_LIMIT_REACHED]
    assert (alarm.alarm_class, alarm.severity) == (AlarmClass.AXIS, Severity.WARNING)
    # jogging on toward the limit does not move; away from it clears the warning
    write(k, "jog_plus", False)
    write(k, "operation_mode", ManualOperationMode.INCREMENTAL)
    write(k, "increment", 20_000)
    record_until_rest(k, ("jog_minus", True))
    assert x_01um(k) == (LIMIT_MAX_MM - 2) * 10_000 and not view(k).limit_warning


def test_an_increment_beyond_the_limit_stops_at_it(k) -> None:
    manual(k)
    write(k, "operation_mode", ManualOperationMode.INCREMENTAL)
    write(k, "increment", 100_000)  # 10 mm, the limit is at -5 mm
    assert write(k, "jog_minus", True) is None
    assert view(k).limit_warning  # known when the goal is cut
    record_until_rest(k)
    assert x_01um(k) == LIMIT_MIN_MM * 10_000


def test_handwheel_moves_by_pulses_times_resolution_and_survives_wrap_around(k) -> None:
    manual(k)
    write(k, "handwheel", 0x7FFF_FFFE)  # outside handwheel mode: only taken
    assert x_01um(k) == 0 and view(k).handwheel_counter == 0x7FFF_FFFE
    write(k, "operation_mode", ManualOperationMode.HANDWHEEL)
    write(k, "resolution", 25)  # 2.5 um per pulse
    record_until_rest(k, ("handwheel", 0x7FFF_FFFF),  # +1
                      ("handwheel", -0x8000_0000 + 2))  # +3 across the wrap
    assert x_01um(k) == 4 * 25
    assert k.kernel.snapshot.channels[0].manual[0].hr_aufloesung == 25
    record_until_rest(k, ("handwheel", -0x8000_0000 - 8 + 0x1_0000_0000))  # -10 back
    assert x_01um(k) == 4 * 25 - 10 * 25
    refusal = write(k, "resolution", 0)
    assert refusal is not None and refusal.reason == RefusalReason.INVALID_VALUE
    refusal = write(k, "jog_plus", True)  # keys do nothing in handwheel mode
    assert refusal is not None and "handwheel" in refusal.message


def test_jog_is_refused_where_the_channel_cannot_move_by_hand(k) -> None:
    write(k, "operation_mode", ManualOperationMode.CONTINUOUS)
    refusal = write(k, "jog_plus", True)  # STANDBY, not MANUAL
    assert refusal is not None and refusal.reason == RefusalReason.NOT_READY
    assert "MANUAL" in refusal.message
    manual(k)
    write(k, "operation_mode", ManualOperationMode.NONE)
    refusal = write(k, "jog_plus", True)
    assert refusal is not None and "operation mode" in refusal.message
    refusal = write(k, "operation_mode", 7)
    assert refusal is not None and refusal.reason == RefusalReason.INVALID_VALUE
    # HOLD: the jog brakes, further jogs are refused until START
    write(k, "operation_mode", ManualOperationMode.CONTINUOUS)
    moving = (lambda v: v.velocity_um_s > 5_000, Feedhold(0, True))
    samples = record_until_rest(k, ("jog_plus", True), then=moving)
    assert max(v for _, v in samples) > 5.0
    assert_ramps(samples, ACC_MM_S2)
    assert k.kernel.snapshot.channels[0].state == ChannelState.HOLD
    refusal = write(k, "jog_minus", True)
    assert refusal is not None and "held" in refusal.message
    assert k.command(StartProgram(0, True)) is None  # START ends the hold
    k.wait_for(lambda s: s.channels[0].state == ChannelState.READY)
    assert write(k, "jog_minus", True) is None
    assert k.command(ResetChannel(0, True)) is None  # RESET: stop at once
    assert not view(k).moving and not view(k).jog_minus


def test_homing_by_object_moves_to_pos_refpkt_at_homing_speed(k) -> None:
    manual(k)
    assert not view(k).referenced
    samples = record_until_rest(k, ("homing_start", True))
    assert_ramps(samples, ACC_MM_S2)
    assert max(abs(v) for _, v in samples) == pytest.approx(HOMING_MM_S)
    assert x_01um(k) == REF_MM * 10_000
    assert view(k).referenced and not view(k).homing_active
    assert not view(k, 1).referenced  # Y was not homed


def test_programs_need_referenced_axes_when_the_machine_parameter_says_so() -> None:
    # issue 39: the machine parameter is the default of every axis' P-AXIS-00277; the
    # program starts and its first block that moves an unreferenced axis is the error
    config = machine(programs_need_referenced_axes=True)
    with KernelHarness({"p.nc": "G01 X1 F600\nM30\n"}, config=config) as k:
        assert k.command(SelectProgram(0, "p.nc")) is None
        run = k._run(StartProgram(0, True), False, 30)
        assert run.channel.state == ChannelState.ERROR
        [error] = run.channel.errors.entries
        assert (error.id, error.file, error.line) == (50110, "p.nc", 1)
        assert "axis X is not referenced" in error.text
        k.command(ResetChannel(0, True))
        manual(k)
        for axis in range(3):
            assert write(k, "homing_start", True, axis) is None
        k.wait_for(lambda s: all(m.referenced for m in s.channels[0].manual))
        assert k.command(SelectProgram(0, "p.nc")) is None
        run = k._run(StartProgram(0, True), False, 30)
        assert run.channel.state == ChannelState.READY


def test_by_default_programs_run_without_homing(k) -> None:
    run = k.run("G01 X1 F600\nM30\n")
    assert run.channel.state == ChannelState.READY
    assert not view(k).referenced


def test_hb_display_state_follows_the_mode_and_operation_mode(k) -> None:
    assert view(k).state == 0
    manual(k)
    assert view(k).state == 1 and view(k).control_element == 0
    write(k, "operation_mode", ManualOperationMode.HANDWHEEL)
    assert (view(k).state, view(k).operation_mode, view(k).control_element) == (2, 1, 1)
    assert k.command(SelectMode(0, ChannelMode.MDI)) is None
    assert view(k).state == 0


def test_g74_in_a_program_homes_the_axes_in_its_sequence(k) -> None:
    k.mdi("G01 X-2 Y4 Z1 F600")
    run = k.run("N10 G74 Z1\nN20 G74 X1 Y1\nN30 G01 X5 F600\nM30\n", record=True)
    assert run.channel.state == ChannelState.READY, run.channel.errors.entries
    assert [m.referenced for m in run.channel.manual] == [True, True, True]
    # Z homed alone first (to 0), then X (to its pos_refpkt 3 mm) and Y together
    z_home = next(n for n, s in enumerate(run.samples) if s.positions_mm[2] == 0.0)
    assert run.samples[z_home].positions_mm[:2] == pytest.approx((-2.0, 4.0))
    assert any(s.positions_mm[:2] == pytest.approx((3.0, 0.0)) for s in run.samples)
    assert run.positions_mm == pytest.approx((5.0, 0.0, 0.0))
    # the path speed of the homing block of X and Y is the lower homing speed: Y's
    # default 10 mm/s (X has 15)
    home_block = [s for s in run.samples if s.block_count == 1]
    assert max(s.path_velocity_mm_s for s in home_block) == pytest.approx(10.0)


def test_g74_in_mdi_references_an_axis_already_at_its_reference_position(k) -> None:
    run = k.mdi("G74 Y1")
    assert run.channel.state == ChannelState.READY
    assert [m.referenced for m in run.channel.manual] == [False, True, False]


@pytest.mark.parametrize(("text", "column", "words"), [
    ("G74", 1, "needs the axes"),
])
def test_bad_g74_blocks_stop_with_20136_naming_the_place(k, text, column, words) -> None:
    k.command(ResetChannel(0, True))
    run = k.run(f"N10 G01 X1 F600\n{text}\nM30\n", name="bad.nc")
    assert run.channel.state == ChannelState.ERROR
    [error] = run.channel.errors.entries
    assert (error.id, error.file, error.line, error.column) == (20136, "bad.nc", 2, column)
    assert words in error.text
    assert run.positions_mm[0] == pytest.approx(1.0)  # the blocks before it ran
    k.command(ResetChannel(0, True))


def test_suspending_the_axis_output_stops_a_jog_and_refuses_the_next(k) -> None:
    manual(k)
    write(k, "operation_mode", ManualOperationMode.CONTINUOUS)
    moving = (lambda v: v.velocity_um_s > 5_000, SetSuspendCommand(0, True))
    samples = record_until_rest(k, ("jog_plus", True), then=moving)
    stopped_mm = samples[-1][0]
    assert 0.0 < stopped_mm < LIMIT_MAX_MM and not view(k).moving
    assert k.kernel.snapshot.channels[0].suspend.output_suspended
    refusal = write(k, "jog_plus", True)
    assert refusal is not None and "not linked" in refusal.message
    assert k.command(SetSuspendCommand(0, False)) is None
    k.wait_for(lambda s: not s.channels[0].suspend.output_suspended)


def test_true_on_a_pressed_key_renews_it_and_is_no_new_press(k) -> None:
    """The service's dead-man has a held key renewed by TRUE written again: no further
    increment, a continuous jog runs on (and one stopped at the limit stays there)."""
    manual(k)
    write(k, "operation_mode", ManualOperationMode.INCREMENTAL)
    write(k, "increment", 10_000)  # 1 mm
    record_until_rest(k, ("jog_plus", True))
    assert x_01um(k) == 10_000
    record_until_rest(k, ("jog_plus", True))  # a renewal: no second increment
    assert x_01um(k) == 10_000 and view(k).jog_plus
    assert write(k, "jog_plus", False) is None
    record_until_rest(k, ("jog_plus", True))  # a new press after the release
    assert x_01um(k) == 20_000
    assert write(k, "jog_plus", False) is None
    write(k, "operation_mode", ManualOperationMode.CONTINUOUS)
    record_until_rest(k, ("jog_plus", True))  # runs to the software limit
    assert x_01um(k) == LIMIT_MAX_MM * 10_000 and view(k).limit_warning
    state = k.kernel.snapshot.channels[0].state
    assert write(k, "jog_plus", True) is None  # renewed at the limit: nothing starts
    assert not view(k).moving and k.kernel.snapshot.channels[0].state == state
