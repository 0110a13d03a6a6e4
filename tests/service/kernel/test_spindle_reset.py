"""RESET and ERROR stop the spindle and drop the pending M functions, cycle by cycle.

ISG P-AXIS-00455 (``kenngr.no_stop_by_channel_reset``, default 0): a spindle turning by
M3, M4 or M19 is stopped at a channel reset; with 1 it keeps turning. An error aborts
the program (reaction class 2): the path stops, and so does the spindle here; what was
output waits for nobody. The real kernel on the virtual clock, every cycle recorded.
"""

from __future__ import annotations

from typing import Any

import pytest

from cnc_objects.service.config import build_config
from cnc_objects.service.kernel.channel_mode import ChannelState
from cnc_objects.service.kernel.commands import ResetChannel
from cnc_objects.service.kernel.spindle import DEG_S2_PER_RPM_S, SpindleMode, SpindleState
from cnc_objects.service.kernel.state import Snapshot
from cnc_objects.service.machine_config import DEFAULT_MACHINE
from tests.support.kernel import KernelHarness
from tests.support.plc_recorder import KINDS, Recorder

RPM = 1200.0


def _config(no_stop: bool = False) -> Any:
    channels = [dict(c) for c in DEFAULT_MACHINE["channels"]]
    channels[0]["techno"] = {"m_synch": KINDS, "auto_acknowledge": False}
    if no_stop:
        channels[0]["techno"]["spindel"] = {"no_stop_by_channel_reset": True}
    return build_config({"channels": channels})


def _spindle(s: Snapshot) -> SpindleState:
    return s.channels[0].spindle


def _braking_cycles(h: KernelHarness, rpm: float) -> tuple[float, int]:
    """The speed lost per cycle, and the cycles from ``rpm`` to standstill."""
    step = h.config.channels[0].techno.spindel.a_max / DEG_S2_PER_RPM_S * h.config.cycle_ms / 1e3
    return step, round(rpm / step)


def _brakes_cycle_by_cycle(h: KernelHarness, rec: Recorder, first: Snapshot) -> None:
    """From ``first`` on (the RESET's or the ERROR's cycle), every cycle: M05, commanded
    0, the speed falls by the ramp's step until it is 0 and reached; it stays 0."""
    step, cycles = _braking_cycles(h, RPM)
    h.wait_for(lambda s: s.cycle >= first.cycle + cycles + 5)
    rows = [s for s in rec.rows if s.cycle >= first.cycle]
    for k, s in enumerate(rows[: cycles + 5]):
        assert s.cycle == first.cycle + k  # every cycle published: the ramp runs in time
        sp = _spindle(s)
        assert (sp.mode, sp.commanded_rpm) == (SpindleMode.M05, 0.0), s.cycle
        assert sp.actual_rpm == pytest.approx(max(RPM - (k + 1) * step, 0.0), abs=1e-6), k
        assert sp.reached == (sp.actual_rpm == 0.0)
    assert _spindle(rows[cycles - 1]).actual_rpm == 0.0


def test_reset_brakes_the_spindle_and_drops_the_pending_m_function() -> None:
    with KernelHarness(config=_config()) as h:
        rec = Recorder(h)
        # M11 is MVS_SVS: output at X10, the path waits there for the PLC's acknowledge
        h.start(f"S{RPM:g} M3\nG01 X10 F6000\nG01 X20 M11\nM30\n")
        waiting = h.wait_for(lambda s: s.channels[0].plc_functions.used_units == 1
                             and _spindle(s).actual_rpm == RPM)
        assert waiting.channels[0].state == ChannelState.ACTIVE
        assert h.command(ResetChannel(0, True)) is None
        reset = rec.first(lambda s: s.cycle > waiting.cycle
                          and s.channels[0].state != ChannelState.ACTIVE)
        units = reset.channels[0].plc_functions
        assert units.used_units == 0 and all(u.acknowledged for u in units.units)
        before = [s for s in rec.rows if s.cycle < reset.cycle][-1]
        assert _spindle(before).actual_rpm == RPM  # turning until the RESET's cycle
        _brakes_cycle_by_cycle(h, rec, reset)
        assert _spindle(h.kernel.snapshot).programmed_rpm == RPM  # S stays stored


def test_error_brakes_the_spindle() -> None:
    with KernelHarness(config=_config()) as h:
        rec = Recorder(h)
        end = h.run(f"S{RPM:g} M3\nG01 X10 F6000\nG01 X20 Q=\nM30\n")
        assert end.channel.state == ChannelState.ERROR
        failed = rec.first(lambda s: s.channels[0].state == ChannelState.ERROR)
        before = rec.first(lambda s: s.cycle == failed.cycle - 1)
        assert _spindle(before).actual_rpm == RPM
        _brakes_cycle_by_cycle(h, rec, failed)
        assert h.kernel.snapshot.channels[0].state == ChannelState.ERROR  # until RESET


def test_no_stop_by_channel_reset_keeps_the_spindle_turning() -> None:
    with KernelHarness(config=_config(no_stop=True)) as h:
        rec = Recorder(h)
        h.start(f"S{RPM:g} M3\nG01 X100 F600\nM30\n")
        turning = h.wait_for(lambda s: _spindle(s).actual_rpm == RPM)
        assert h.command(ResetChannel(0, True)) is None
        reset = rec.first(lambda s: s.cycle > turning.cycle
                          and s.channels[0].state != ChannelState.ACTIVE)
        _, cycles = _braking_cycles(h, RPM)
        h.wait_for(lambda s: s.cycle >= reset.cycle + cycles + 5)
        assert all(_spindle(s).mode == SpindleMode.M03 and _spindle(s).actual_rpm == RPM
                   for s in rec.rows if s.cycle >= reset.cycle)
