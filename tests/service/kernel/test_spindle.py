"""The channel's spindle in the kernel: S, M3/M4/M5/M19, override, the ramp, and the
path waiting for the speed (spindel[0].m3_synch = MVS_SVS, the embedded default).

The real kernel on the virtual clock; every published cycle is recorded.
"""

from __future__ import annotations

import pytest

from cnc_objects.service.config import build_config
from cnc_objects.service.kernel.channel_mode import ChannelState
from cnc_objects.service.kernel.commands_technology import SetSpindleOverride
from cnc_objects.service.kernel.spindle import DEG_S2_PER_RPM_S, SpindleMode, SpindleState
from cnc_objects.service.kernel.state import Snapshot
from cnc_objects.service.machine_config import DEFAULT_MACHINE
from tests.support.kernel import KernelHarness
from tests.support.plc_recorder import Recorder


def _spindle(s: Snapshot) -> SpindleState:
    return s.channels[0].spindle


def test_s_alone_stores_the_speed_and_does_not_turn() -> None:
    with KernelHarness() as h:
        h.run("S1000\nM30\n")
        sp = _spindle(h.kernel.snapshot)
        assert (sp.mode, sp.programmed_rpm, sp.actual_rpm) == (SpindleMode.M05, 1000.0, 0.0)


def test_m3_ramps_up_and_the_motion_waits_for_the_speed() -> None:
    with KernelHarness() as h:
        rec = Recorder(h)
        end = h.run("G01 X10 F6000 S3000 M3\nM30\n").final
        a_rpm_s = h.config.channels[0].techno.spindel.a_max / DEG_S2_PER_RPM_S
        cycle_s = h.config.cycle_ms / 1000.0
        started = rec.first(lambda s: _spindle(s).commanded_rpm == 3000.0)
        reached = rec.first(lambda s: _spindle(s).actual_rpm == 3000.0)
        ramp_cycles = reached.cycle - started.cycle
        assert ramp_cycles == pytest.approx(3000.0 / a_rpm_s / cycle_s, abs=1)
        moving = rec.first(lambda s: s.channels[0].axes[0].position_mm > 0.0)
        assert moving.cycle > reached.cycle  # MVS_SVS: no motion before the speed
        # in between the actual speed rises by a * cycle each cycle
        mid = rec.first(lambda s: s.cycle == started.cycle + 10)
        assert _spindle(mid).actual_rpm == pytest.approx(11 * a_rpm_s * cycle_s, rel=1e-6)
        assert end.channels[0].state == ChannelState.READY
        assert _spindle(end).mode == SpindleMode.M03  # no M5: the spindle keeps turning


def test_m4_turns_backwards_and_m5_stops() -> None:
    with KernelHarness() as h:
        h.run("S600 M4\nM30\n")
        assert _spindle(h.kernel.snapshot).actual_rpm == -600.0
        h.run("M5\nM30\n")
        sp = _spindle(h.kernel.snapshot)
        assert (sp.mode, sp.actual_rpm, sp.reached) == (SpindleMode.M05, 0.0, True)


def test_m19_brakes_and_orients() -> None:
    with KernelHarness() as h:
        h.run("S600 M3\nM19\nM30\n")
        sp = _spindle(h.kernel.snapshot)
        assert (sp.mode, sp.actual_rpm, sp.position_deg, sp.reached) == (
            SpindleMode.M19, 0.0, 0.0, True)


def test_override_scales_the_speed_and_is_range_checked() -> None:
    with KernelHarness() as h:
        assert h.command(SetSpindleOverride(0, 500)) is None
        h.run("S2000 M3\nM30\n")
        assert _spindle(h.kernel.snapshot).actual_rpm == 1000.0
        refusal = h.command(SetSpindleOverride(0, 1501))
        assert refusal is not None and "outside 0..150 %" in refusal.message


def test_m3_without_s_is_no_error_and_does_not_turn() -> None:
    """ISG: rotation needs M3 *and* a valid speed; M3 alone is no error."""
    with KernelHarness() as h:
        run = h.run("M3\nG01 X1 F6000\nM30\n")
        assert run.channel.state == ChannelState.READY
        sp = _spindle(run.final)
        assert (sp.mode, sp.actual_rpm) == (SpindleMode.M03, 0.0)


def test_s_with_s_synch_mvs_svs_waits_for_the_new_speed() -> None:
    """spindel[0].s_synch = MVS_SVS: a changed S in a motion block holds the motion until
    the spindle has the speed (IS/tf5200_spindle/287528075.html)."""
    channels = [dict(c) for c in DEFAULT_MACHINE["channels"]]
    channels[0]["techno"] = {"spindel": {"s_synch": "MVS_SVS"}}
    with KernelHarness(config=build_config({"channels": channels})) as h:
        h.run("S1000 M3\nM30\n")
        rec = Recorder(h)
        h.run("G01 X10 F6000 S3000\nM30\n")
        reached = rec.first(lambda s: _spindle(s).actual_rpm == 3000.0)
        moving = rec.first(lambda s: s.channels[0].axes[0].position_mm > 0.0)
        assert moving.cycle > reached.cycle
        units = h.kernel.snapshot.channels[0].plc_functions.units
        assert [(u.number, u.acknowledged) for u in units] == [(1000, True), (3000, True)]


@pytest.mark.parametrize(("line", "error_id", "column"), [
    ("S1000 M3 M5", 20155, 10),  # ISG: a second spindle M function in the block
    ("G01 X10 F600 S100 M5 M19", 20155, 22),  # M19 goes with M3/M4, never with M5
    ("G01 X10 F600 M8 M8", 20765, 17),  # ISG: the same M function twice in a block
])
def test_a_block_with_two_spindle_m_functions_or_one_m_twice_is_an_isg_error(
        line: str, error_id: int, column: int) -> None:
    with KernelHarness() as h:
        run = h.run(f"G01 X1 F600\n{line}\nM30\n")
        assert run.channel.state == ChannelState.ERROR
        error = run.channel.errors.entries[0]
        assert (error.id, error.line, error.column) == (error_id, 2, column)
        assert _spindle(h.kernel.snapshot).mode == SpindleMode.M05  # nothing was output


def test_a_syntax_check_lists_both_and_goes_on() -> None:
    from cnc_objects.protocol.values import ExecutionMode
    from cnc_objects.service.kernel.commands import SetExecutionMode

    with KernelHarness() as h:
        check = int(ExecutionMode.SYNCHK | ExecutionMode.MACHINE_LOCK)
        assert h.command(SetExecutionMode(0, check)) is None
        run = h.run("S1000 M3 M5\nM8 M8\nG01 X1 F600\nM30\n")
        found = [(e.id, e.line) for e in run.channel.errors.entries if e.id != 21309]
        assert found == [(20155, 1), (20765, 2)]
