"""ISG's spindle-specific syntax ``S[...]`` in the kernel (issue 39, departure 5), and
ISG's rule that M19 needs a speed > 0 (IS/tf5200_programming_manual/208198923.html).

The real kernel on the virtual clock; every published cycle is recorded. ``S[...]`` must
do cycle for cycle what the plain block form does (same words, same PLC handshake).
"""

from __future__ import annotations

from typing import Any

import pytest

from cnc_objects.service.kernel.channel_mode import ChannelState
from cnc_objects.service.kernel.commands import ResetChannel
from cnc_objects.service.kernel.spindle import SpindleMode, SpindleState
from cnc_objects.service.kernel.state import Snapshot
from tests.support.kernel import KernelHarness
from tests.support.plc_recorder import Recorder


def _spindle(s: Snapshot) -> SpindleState:
    return s.channels[0].spindle


def _cycles(text: str) -> list[tuple[Any, ...]]:
    """Every cycle of ``text`` on a fresh kernel from START to READY: spindle state, X,
    path velocity, the PLC's units (type, number, kind, acknowledged)."""
    with KernelHarness() as h:
        rec = Recorder(h)
        run = h.run(text)
        assert run.channel.state == ChannelState.READY, run.channel.errors.entries
        rows = list(rec.rows)
        start = next(k for k, s in enumerate(rows) if s.channels[0].state == ChannelState.ACTIVE)
        end = next(k for k in range(start, len(rows))
                   if rows[k].channels[0].state == ChannelState.READY)
        first = rows[start].cycle
        return [(s.cycle - first, _spindle(s), s.channels[0].axes[0].position_mm,
                 s.channels[0].path.path_velocity_mm_s,
                 [(u.type, u.number, u.sync, u.acknowledged)
                  for u in s.channels[0].plc_functions.units])
                for s in rows[start:end + 1]]


def test_s_bracket_runs_cycle_for_cycle_as_the_plain_block() -> None:
    plain = _cycles("G01 X10 F6000 S3000 M3 M8 H20\nG01 X20 S1000 M4\n"
                    "G01 X21 S.POS=45 M19\nM30\n")
    bracket = _cycles("G01 X10 F6000 S[M3 REV3000 M8 H20]\nG01 X20 S[REV1000 M4]\n"
                      "G01 X21 S[POS=45 M19]\nM30\n")
    assert len(plain) > 100
    assert bracket == plain
    assert plain[-1][1].position_deg == 45.0


def test_isg_positioning_example_runs_with_pos_modal() -> None:
    """IS/tf5200_programming_manual/208198923.html, N10..N90 as printed."""
    with KernelHarness() as h:
        rec = Recorder(h)
        run = h.run("N10 S[REV100 POS45 M19 M3]\nN20 S[M03 REV1000]\nN30 S[M19 M4 REV150]\n"
                    "N40 S[M05]\nN50 S[M19]\nN60 S[REV200 M19 POS90]\nN70 S[M03 REV1000]\n"
                    "N80 S[M05]\nN90 M30\n")
        assert run.channel.state == ChannelState.READY, run.channel.errors.entries
        oriented = [(sp.programmed_rpm, sp.position_deg) for sp in map(_spindle, rec.rows)
                    if sp.mode == SpindleMode.M19 and sp.reached]
        # N10 at 100 rpm to 45, N30/N50 at 150 rpm to 45 (POS modal), N60 at 200 to 90
        assert sorted(set(oriented)) == [(100.0, 45.0), (150.0, 45.0), (200.0, 90.0)]
        turning = {sp.mode for sp in map(_spindle, rec.rows) if sp.actual_rpm > 0.0}
        # N20/N70 turn cw; M19 and M05 brake with the ramp
        assert turning == {SpindleMode.M03, SpindleMode.M19, SpindleMode.M05}
        sp = _spindle(run.final)
        assert (sp.mode, sp.actual_rpm, sp.programmed_rpm) == (SpindleMode.M05, 0.0, 1000.0)


def test_m19_needs_a_speed_and_takes_the_stored_one_of_an_earlier_run() -> None:
    with KernelHarness() as h:
        run = h.run("G01 X1 F600\nM19 S.POS=90\nM30\n")
        assert run.channel.state == ChannelState.ERROR
        e = run.channel.errors.entries[0]
        assert (e.id, e.line, e.column) == (20156, 2, 1)
        assert _spindle(run.final).mode == SpindleMode.M05  # nothing was output
        assert h.command(ResetChannel(0, True)) is None
        h.run("S500\nM30\n")  # stored, the spindle does not turn (M05)
        run = h.run("S[M19 POS90]\nM30\n")  # ISG: "a valid spindle speed must be set"
        assert run.channel.state == ChannelState.READY, run.channel.errors.entries
        sp = _spindle(run.final)
        assert (sp.mode, sp.position_deg, sp.reached) == (SpindleMode.M19, 90.0, True)


@pytest.mark.parametrize(("line", "error_id", "column"), [
    ("S[M3 REV100 FOO]", 21035, 13),  # ISG: unknown command in the spindle sequence
    ("S[M3 REV]", 20110, 6),  # a keyword without its value
    ("S[M3 REV100 M4]", 20155, 13),  # two spindle M functions
    ("S[M5 REV100 M19]", 20155, 13),  # M19 never with M5
    ("G01 X2 S[M3 REV100", 20200, 8),  # the bracket is not closed
    ("S[REV-100 M3]", 20991, 3),  # ISG: negative spindle speed in S[...]
    ("S[REV100 POS1 POS2]", 20851, 15),  # ISG: the spindle position twice
    ("S100 M19 S.POS=2 S[POS1]", 20851, 20),
    ("S[M3 REV100 D1]", 21243, 13),  # ISG: D inside the main spindle's bracket
    ("S[REV100 OVERRIDE=50]", 20500, 10),  # ISG lists it; the twin has no such part
    ("S[REV100 G74]", 20500, 10),
    ("S[M19]", 20156, 3),  # no speed > 0 set
])
def test_bad_spindle_brackets_are_isg_errors_at_their_token(
        line: str, error_id: int, column: int) -> None:
    with KernelHarness() as h:
        run = h.run(f"G01 X1 F600\n{line}\nM30\n")
        assert run.channel.state == ChannelState.ERROR
        e = run.channel.errors.entries[0]
        assert (e.id, e.line, e.column) == (error_id, 2, column)
        assert e.file.endswith("test.nc")
        assert _spindle(run.final).mode == SpindleMode.M05  # nothing was output
