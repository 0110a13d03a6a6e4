"""M functions with the PLC, cycle by cycle: each synchronisation kind's timing.

The real kernel on the virtual clock with ``auto_acknowledge`` off: the test plays the
PLC (AcknowledgeTechnoUnit). Every published cycle is recorded, so each claim is about
cycle numbers: when the function is output, where the path stands while it waits, and
that motion goes on in the very cycle the PLC's acknowledge is applied (commands are
applied at the start of a cycle, before the path's step). The embedded PLC acknowledges
at the end of a cycle, so there the motion goes on in the next one.
"""

from __future__ import annotations

from typing import Any

import pytest

from cnc_objects.protocol.values import ExecutionMode
from cnc_objects.service.config import build_config
from cnc_objects.service.kernel.channel_mode import ChannelState
from cnc_objects.service.kernel.commands import SetExecutionMode
from cnc_objects.service.kernel.commands_technology import AcknowledgeTechnoUnit
from cnc_objects.service.kernel.state import Snapshot
from cnc_objects.service.machine_config import DEFAULT_MACHINE, SyncKind
from tests.support.kernel import KernelHarness
from tests.support.plc_recorder import KINDS, Recorder


def _config(auto: bool = False, time_us: int = 0) -> Any:
    channels = [dict(c) for c in DEFAULT_MACHINE["channels"]]
    channels[0]["techno"] = {"m_synch": KINDS, "auto_acknowledge": auto,
                             "prozess_zeit_default": time_us}
    return build_config({"channels": channels})




def _x(s: Snapshot) -> float:
    return s.channels[0].axes[0].position_mm


def _units(s: Snapshot) -> Any:
    return s.channels[0].plc_functions.units


def _passes(rec: Recorder, s: Snapshot, x_mm: float) -> bool:
    """The path passed ``x_mm`` in cycle ``s`` (it runs through: the end of the cycle
    is past it)."""
    before = rec.first(lambda r: r.cycle == s.cycle - 1)
    return _x(before) < x_mm <= _x(s)


def _pending(s: Snapshot) -> bool:
    return s.channels[0].plc_functions.used_units > 0


PROGRAM = "G01 X10 F6000\nN20 G01 X20 M{m}\nN30 G01 X30\nM30\n"


def _run_until_output(h: KernelHarness, m: int) -> tuple[Recorder, Snapshot]:
    """Start the program; the recorder and the first cycle that shows the output."""
    rec = Recorder(h)
    h.start(PROGRAM.format(m=m))
    h.wait_for(lambda s: bool(_units(s)) or s.channels[0].state == ChannelState.ERROR)
    return rec, rec.first(lambda s: bool(_units(s)))


def _ack(h: KernelHarness, rec: Recorder) -> Snapshot:
    """Acknowledge unit 0 as the PLC; the first cycle that shows it acknowledged."""
    assert h.command(AcknowledgeTechnoUnit(0, 0)) is None
    h.wait_for(lambda s: not _pending(s))
    return rec.first(lambda s: _units(s) and not _pending(s))


def test_mvs_svs_output_before_the_motion_which_waits_for_the_acknowledge() -> None:
    with KernelHarness(config=_config()) as h:
        rec, out = _run_until_output(h, 11)
        unit = _units(out)[0]
        assert (unit.number, unit.sync, unit.acknowledged) == (11, SyncKind.MVS_SVS, False)
        assert _x(out) == 10.0 and out.channels[0].path.path_velocity_mm_s == 0.0
        h.wait_for(lambda s: s.cycle >= out.cycle + 50)  # the PLC takes 50 cycles or more
        acked = _ack(h, rec)
        waited = [s for s in rec.rows if out.cycle <= s.cycle < acked.cycle]
        assert all(_x(s) == 10.0 for s in waited)  # no motion until the acknowledge
        assert rec.first(lambda s: _x(s) > 10.0).cycle == acked.cycle
        assert h.wait().channel.state == ChannelState.READY


def test_mvs_sns_output_before_the_motion_waited_for_at_the_block_end() -> None:
    with KernelHarness(config=_config()) as h:
        rec, out = _run_until_output(h, 12)
        assert _passes(rec, out, 10.0)  # output where the block's motion starts ...
        h.wait_for(lambda s: _x(s) == 20.0 and s.channels[0].path.path_velocity_mm_s == 0.0)
        before_ack = h.wait_for(lambda s: s.cycle >= rec.first(lambda r: _x(r) == 20.0).cycle
                                + 50)
        assert _x(before_ack) == 20.0 and _pending(before_ack)  # ... stands at its end
        moving_early = [s for s in rec.rows if out.cycle < s.cycle and 10.0 < _x(s) < 20.0]
        assert moving_early  # the motion ran while the function was pending
        acked = _ack(h, rec)
        assert rec.first(lambda s: _x(s) > 20.0).cycle == acked.cycle
        assert h.wait().channel.state == ChannelState.READY


def test_mns_sns_output_at_the_block_end_and_waited_for_there() -> None:
    with KernelHarness(config=_config()) as h:
        rec, out = _run_until_output(h, 13)
        assert _x(out) == 20.0 and out.channels[0].path.path_velocity_mm_s == 0.0
        assert not any(_units(s) for s in rec.rows if _x(s) < 20.0)  # not before the end
        h.wait_for(lambda s: s.cycle >= out.cycle + 50)
        acked = _ack(h, rec)
        assert all(_x(s) == 20.0 for s in rec.rows if out.cycle <= s.cycle < acked.cycle)
        assert rec.first(lambda s: _x(s) > 20.0).cycle == acked.cycle
        assert h.wait().channel.state == ChannelState.READY


def test_mos_output_without_waiting() -> None:
    with KernelHarness(config=_config()) as h:
        rec, out = _run_until_output(h, 10)
        unit = _units(out)[0]
        assert (unit.sync, unit.acknowledged) == (SyncKind.MOS, True)
        assert _passes(rec, out, 10.0)  # output at the start of N20's motion
        assert h.wait().channel.state == ChannelState.READY  # no acknowledge needed
        stands = [s for s in rec.rows if 10.0 < _x(s) < 30.0
                  and s.channels[0].path.path_velocity_mm_s == 0.0]
        assert stands == []  # the path never stopped on the way


def test_no_synch_is_not_output() -> None:
    with KernelHarness(config=_config()) as h:
        h.run(PROGRAM.format(m=14))
        assert _units(h.kernel.snapshot) == ()


@pytest.mark.parametrize("time_us", [0, 20_000])
def test_the_embedded_plc_acknowledges_after_the_function_time(time_us: int) -> None:
    with KernelHarness(config=_config(auto=True, time_us=time_us)) as h:
        rec = Recorder(h)
        assert h.run(PROGRAM.format(m=11)).channel.state == ChannelState.READY
        out = rec.first(lambda s: bool(_units(s)))
        acked = rec.first(lambda s: _units(s) and not _pending(s))
        cycle_s = h.config.cycle_ms / 1000.0
        assert acked.cycle - out.cycle == round(time_us / 1e6 / cycle_s)
        assert rec.first(lambda s: _x(s) > 10.0).cycle == acked.cycle + 1


def test_an_acknowledge_of_nothing_pending_is_refused() -> None:
    with KernelHarness(config=_config()) as h:
        refusal = h.command(AcknowledgeTechnoUnit(0, 0))
        assert refusal is not None and "does not exist" in refusal.message


def test_prod_time_outputs_nothing_and_waits_for_no_plc() -> None:
    """The machining time calculation runs through without a PLC acknowledge."""
    with KernelHarness(config=_config()) as h:
        assert h.command(SetExecutionMode(0, ExecutionMode.PROD_TIME)) is None
        run = h.run(PROGRAM.format(m=11))
        assert run.channel.state == ChannelState.READY
        assert _units(run.final) == ()
        assert run.channel.path.program_time_s > 0.0
