"""Syntax check (SYNCHK), dry run (MACHINE_LOCK) and machining time (PROD_TIME) in the
real kernel on the virtual clock (FCT-C9)."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pytest

from bench.decoder_bench import generate_program
from cnc_objects.service.kernel.channel_mode import ChannelState
from cnc_objects.service.kernel.commands import (
    Feedhold,
    ResetChannel,
    SetExecutionMode,
    SetExecutionModeEnable,
    SetExecutionModePlc,
    SetFeedOverride,
    SetSingleBlock,
    SetSyntaxCheckParameter,
    StartProgram,
)
from cnc_objects.service.kernel.state import DecoderFlag
from tests.support.kernel import KernelHarness

SYNCHK, MACHINE_LOCK, PROD_TIME = 0x8, 0x40, 0x10
SUPPRESS_TECHNO_OUTPUT = 0x2000

EXAMPLE_PATH = Path(__file__).resolve().parents[3] / "docs" / "examples" / "check-syntax.nc"
# the example program of the function description (FCT-C9), character for character
EXAMPLE = EXAMPLE_PATH.read_text(encoding="utf-8")
EXAMPLE_ERRORS = [(20113, 5), (20500, 8), (20310, 11), (20151, 14), (20121, 17)]


@pytest.fixture()
def harness():
    """A kernel of its own per test: the tests change modes and parameters."""
    with KernelHarness() as h:
        yield h


def _mode(h: KernelHarness, value: int) -> None:
    assert h.command(SetExecutionMode(0, value)) is None


def _param(h: KernelHarness, name: str, value: int) -> None:
    assert h.command(SetSyntaxCheckParameter(0, name, value)) is None


def _errors(channel) -> list[tuple[int, int]]:
    return [(e.id, e.line) for e in channel.errors.entries if e.id not in (21309, 21310)]


def _positions(snapshot) -> tuple[float, ...]:
    return tuple(a.position_mm for a in snapshot.channels[0].axes)


def test_the_example_program_gives_its_five_errors_and_ends_ready(harness) -> None:
    _mode(harness, SYNCHK | MACHINE_LOCK)
    before = _positions(harness.kernel.snapshot)
    run = harness.run(EXAMPLE, "check_syntax.nc")
    ch = run.channel
    assert ch.state == ChannelState.READY
    assert _errors(ch) == EXAMPLE_ERRORS
    assert all(e.file == "check_syntax.nc" for e in ch.errors.entries)
    assert ch.program.execution_mode_active == SYNCHK | MACHINE_LOCK | SUPPRESS_TECHNO_OUTPUT
    assert _positions(run.final) == before  # no axis moved
    assert ch.block.line == 19 and ch.block.block_number == 130  # the decoder reached N130 M30


def test_synchk_without_machine_lock_warns_21309_and_sets_it(harness) -> None:
    _mode(harness, SYNCHK)
    run = harness.run("G1 X10 F100\nM30\n", "a.nc")
    ch = run.channel
    assert [(e.id, e.warning) for e in ch.errors.entries] == [(21309, True)]
    assert ch.program.execution_mode_active == SYNCHK | MACHINE_LOCK | SUPPRESS_TECHNO_OUTPUT
    assert ch.switches.execution_mode_command == SYNCHK  # the command stays as written
    assert ch.state == ChannelState.READY and _positions(run.final) == (0.0, 0.0, 0.0)


def test_a_mode_takes_effect_at_the_next_program_start(harness) -> None:
    harness.run("G1 X1 F6000\nM30\n", "a.nc")
    _mode(harness, SYNCHK | MACHINE_LOCK)
    snap = harness.kernel.snapshot.channels[0]
    assert snap.switches.execution_mode_command == SYNCHK | MACHINE_LOCK
    assert snap.program.execution_mode_active == 0
    run = harness.run("G1 X2 F6000\nM30\n", "a.nc")
    assert run.channel.program.execution_mode_active & SYNCHK
    assert _positions(run.final)[0] == pytest.approx(1.0)  # the check did not move X


def test_the_plc_command_counts_while_it_enables_the_unit(harness) -> None:
    _mode(harness, 0)
    assert harness.command(SetExecutionModePlc(0, MACHINE_LOCK)) is None
    run = harness.run("G1 X3 F6000\nM30\n", "a.nc")
    assert run.channel.program.execution_mode_active == 0  # not enabled: the HMI's request
    assert run.final.channels[0].axes[0].position_mm == pytest.approx(3.0)
    assert harness.command(SetExecutionModeEnable(0, True)) is None
    run = harness.run("G1 X7 F6000\nM30\n", "a.nc")
    assert run.channel.program.execution_mode_active == MACHINE_LOCK
    assert run.final.channels[0].axes[0].position_mm == pytest.approx(3.0)
    refusal = harness.command(SetExecutionModePlc(0, 0x4))
    assert refusal is not None and "ON_LINE" in refusal.message


def test_a_clean_program_passes_without_errors(harness) -> None:
    _mode(harness, SYNCHK | MACHINE_LOCK)
    run = harness.run(generate_program(3000), "clean.nc")
    assert run.channel.state == ChannelState.READY and run.channel.errors.entries == ()
    assert run.channel.block.block_count > 2500


def test_errors_total_stops_the_check_after_that_many_errors(harness) -> None:
    _mode(harness, SYNCHK | MACHINE_LOCK)
    _param(harness, "errors_total", 2)
    _param(harness, "record_result", 1)
    run = harness.run(EXAMPLE, "check_syntax.nc")
    ch = run.channel
    assert _errors(ch) == EXAMPLE_ERRORS[:2]
    assert ch.errors.entries[-1].id == 21310 and ch.errors.entries[-1].warning
    assert ch.state == ChannelState.READY
    assert ch.block.line == 8  # it ended where the second error was
    log = harness.files["dec01.sc"].decode().splitlines()
    assert log[-3:] == [  # the line of the last error is logged before it, then the end
        "check_syntax.nc:8: N50 #COMMAND UNKNOWN [...]",
        "error 20500 (command) at check_syntax.nc:8:5: #COMMAND is not supported yet",
        "; end: 6 lines, 1 blocks, 2 errors, stopped: syn_chk.errors_total reached"]


def test_many_errors_do_not_go_to_the_error_log_file(harness) -> None:
    _mode(harness, SYNCHK | MACHINE_LOCK)
    text = "".join(f"N{k} G1 X1 F100 Q7\n" for k in range(1, 3001)) + "M30\n"
    run = harness.run(text, "many.nc")
    assert run.channel.errors.count == 3000  # no 21309: MACHINE_LOCK was commanded
    assert len(run.channel.errors.entries) == 7  # the last slot is kept for an error that ends it
    assert b"Q7" not in harness.files.get("errors-ch1.log", b"")


def test_errors_per_block_skips_the_rest_of_the_line(harness) -> None:
    _mode(harness, SYNCHK | MACHINE_LOCK)
    _param(harness, "errors_per_block", 1)
    run = harness.run("G1 X1 Q1 P2 F100\nG1 X2 Q3\nM30\n", "a.nc")
    assert [(e.id, e.line, e.column) for e in run.channel.errors.entries] == [
        (21220, 1, 7), (21220, 2, 7)]


def test_the_log_file_lists_every_checked_line_and_error(harness) -> None:
    _mode(harness, SYNCHK | MACHINE_LOCK)
    _param(harness, "record_result", 1)
    harness.run(EXAMPLE, "check_syntax.nc")
    log = harness.files["dec01.sc"].decode().splitlines()
    assert log[0] == "; syntax check of check_syntax.nc in channel 1"
    assert "check_syntax.nc:5: N40 G01 X10 F1111111111111111" in log
    errors = [line for line in log if line.startswith("error ")]
    assert [e.split(" ")[1] for e in errors] == ["20113", "20500", "20310", "20151", "20121"]
    assert errors[3].startswith("error 20151 (command) at check_syntax.nc:14:19: ")
    # each error follows the line it belongs to
    assert log.index(errors[4]) == log.index("check_syntax.nc:17: N80 G00 G01 X100 F1000") + 1
    assert log[-1] == "; end: 17 lines, 3 blocks, 5 errors, complete"
    # a second check replaces the file
    harness.run("M30\n", "b.nc")
    assert harness.files["dec01.sc"].decode().splitlines()[-1].endswith("0 errors, complete")


def test_interactive_mode_waits_after_each_error(harness) -> None:
    _mode(harness, SYNCHK | MACHINE_LOCK)
    _param(harness, "interactive", 1)
    harness.start("G1 X1 Q1 F100\nG1 X2\nG1 X3 Q2\nM30\n", "a.nc")
    snap = harness.wait_for(lambda s: s.channels[0].state == ChannelState.HOLD)
    ch = snap.channels[0]
    assert ch.block.line == 1 and ch.program.waiting_for_start
    assert ch.program.decoder_flags == DecoderFlag.SYNTAX_CHECK | DecoderFlag.WAIT_AFTER_ERROR
    assert harness.command(StartProgram(0, True)) is None
    snap = harness.wait_for(lambda s: s.channels[0].state == ChannelState.HOLD
                            and s.channels[0].block.line == 3)
    assert snap.channels[0].program.decoder_flags & DecoderFlag.WAIT_AFTER_ERROR
    assert harness.command(ResetChannel(0, True)) is None  # abort
    snap = harness.wait_for(lambda s: s.channels[0].state == ChannelState.READY)
    assert snap.channels[0].program.decoder_flags == 0


def test_single_step_stops_after_every_line_and_the_position_follows(harness) -> None:
    _mode(harness, SYNCHK | MACHINE_LOCK)
    assert harness.command(SetSingleBlock(0, True)) is None
    harness.start("N10 G1 X1 F100\nN20 V.P.A = 1\n\nN40 G1 X2\nM30\n", "a.nc")
    seen = []
    for _ in range(4):
        snap = harness.wait_for(lambda s: s.channels[0].state == ChannelState.HOLD)
        ch = snap.channels[0]
        assert ch.program.decoder_flags & DecoderFlag.WAIT_CONTINUE
        seen.append((ch.block.line, ch.block.block_number, ch.block.file_offset))
        assert harness.command(StartProgram(0, True)) is None
        harness.wait_for(lambda s: s.channels[0].state != ChannelState.HOLD
                         or s.channels[0].block.line != ch.block.line)
    assert seen == [(1, 10, 0), (2, 20, 15), (4, 40, 30), (5, -1, 40)]  # not at blank line 3
    run = harness.wait()
    assert run.channel.state == ChannelState.READY


def test_stop_interrupts_decoding_and_resume_goes_on(harness) -> None:
    _mode(harness, SYNCHK | MACHINE_LOCK)
    text = generate_program(100_000)
    harness.start(text, "long.nc")
    assert harness.command(Feedhold(0, True)) is None
    snap = harness.wait_for(lambda s: s.channels[0].state == ChannelState.HOLD
                            and s.channels[0].program.decoder_flags & DecoderFlag.WAIT_CONTINUE)
    stopped_at = snap.channels[0].block.line
    assert 0 < stopped_at < 100_000
    snap2 = harness.kernel.snapshot.channels[0]
    assert snap2.block.line == stopped_at  # nothing decoded while it stands
    assert harness.command(StartProgram(0, True)) is None
    run = harness.wait()
    assert run.channel.state == ChannelState.READY and run.channel.block.line == 100_000


def test_a_software_limit_violation_aborts_the_check(harness) -> None:
    harness.home()  # the software limits count once the axes are referenced (P-AXIS-00705)
    _mode(harness, SYNCHK | MACHINE_LOCK)
    # both ends inside +-1000 mm, the arc's bulge reaches X 1005
    run = harness.run("G1 X990 F1000\nG2 X990 Y-10 I0 J-5\nG1 Q1\nG2 X990 Y-30 I5 J-10\n"
                      "G1 X0\nM30\n", "a.nc")
    ch = run.channel
    assert ch.state == ChannelState.ERROR
    assert [(e.id, e.line) for e in ch.errors.entries] == [(21220, 3), (50101, 4)]
    assert _positions(run.final) == (0.0, 0.0, 0.0)


def test_the_dry_run_stops_at_its_first_error_and_moves_no_axis(harness) -> None:
    _mode(harness, MACHINE_LOCK)
    run = harness.run("G1 X10 F100\nG4 X100\nM3 S1000\nG1 Q1\nG1 X20\nM30\n", "a.nc")
    ch = run.channel
    assert ch.state == ChannelState.ERROR and [(e.id, e.line) for e in ch.errors.entries] == [(21220, 4)]
    assert _positions(run.final) == (0.0, 0.0, 0.0)
    assert harness.command(ResetChannel(0, True)) is None
    # dwell and motion are not executed: a 100 s dwell ends in a few cycles
    run = harness.run("G1 X10 F1\nG4 X100\nM30\n", "b.nc")
    assert run.channel.state == ChannelState.READY and run.channel.path.program_time_s < 1.0


def test_the_dry_run_ignores_feedhold_override_and_zero_override(harness) -> None:
    _mode(harness, MACHINE_LOCK)
    assert harness.command(SetFeedOverride(0, 0)) is None
    run = harness.run("G1 X10 F100\nG1 X0\nM30\n", "a.nc")
    assert run.channel.state == ChannelState.READY


def test_prod_time_reports_the_time_a_real_run_takes(harness) -> None:
    program = ("N10 G1 X10 Y5 F3000\nG4 X0.25\nG2 X20 Y5 I5 J0\nG1 X0 Y0 F6000\n"
               "G0 X50\nG1 X0 F2000\nM30\n")
    _mode(harness, PROD_TIME)
    timed = harness.run(program, "a.nc")
    assert timed.channel.state == ChannelState.READY
    assert _positions(timed.final) == (0.0, 0.0, 0.0)  # the axes did not move
    _mode(harness, 0)
    real = harness.run(program, "a.nc")
    assert timed.channel.path.program_time_s == pytest.approx(real.channel.path.program_time_s, abs=1e-9)
    assert timed.channel.path.program_time_s > 1.0


def test_prod_time_does_not_wait_at_m0_or_single_block(harness) -> None:
    _mode(harness, PROD_TIME)
    assert harness.command(SetSingleBlock(0, True)) is None
    run = harness.run("G1 X10 F6000\nM0\nG1 X0\nM30\n", "a.nc")
    assert run.channel.state == ChannelState.READY and run.channel.path.program_time_s > 0.2


def test_a_loop_without_blocks_does_not_block_the_cycle_and_reset_ends_it(harness) -> None:
    _mode(harness, SYNCHK | MACHINE_LOCK)
    _param(harness, "record_result", 1)
    harness.start("#VAR\nV.L.I = 0\n#ENDVAR\n$WHILE 1\nV.L.I = V.L.I + 1\n$ENDWHILE\nM30\n",
                  "loop.nc")
    # the decoder pauses for each cycle's budget inside the loop, so commands still apply
    snap = harness.wait_for(lambda s: s.channels[0].block.line == 5)
    assert snap.channels[0].state == ChannelState.ACTIVE
    assert harness.command(ResetChannel(0, True)) is None
    snap = harness.wait_for(lambda s: s.channels[0].state == ChannelState.READY)
    assert snap.channels[0].program.decoder_flags == 0


@pytest.mark.parametrize("after", ["G1 X10\nG40 X0 Y0\nM30\n", "M30\n", "G40\nG1 X0 Y0\nM30\n"])
@pytest.mark.parametrize("mode", [SYNCHK | MACHINE_LOCK, MACHINE_LOCK])
def test_a_compensated_arc_over_a_limit_aborts_as_in_a_real_run(harness, mode, after) -> None:
    harness.home()  # the software limits count once the axes are referenced (P-AXIS-00705)
    # G42 with D3: the compensated arc of line 4 reaches beyond X 1000; the error comes
    # when compensation releases the held arc (next block, G40 or the end of the data)
    _mode(harness, mode)
    run = harness.run("G1 X0 Y0 F6000\nD3 G42 X10 Y0\nG1 X990\nG3 X990 Y20 I0 J10\n" + after,
                      "comp.nc")
    ch = run.channel
    assert ch.state == ChannelState.ERROR
    assert [(e.id, e.line, e.warning) for e in ch.errors.entries if e.id != 21309] == [(50101, 4, False)]


@pytest.mark.parametrize("mode", [SYNCHK, MACHINE_LOCK, PROD_TIME])
def test_manual_blocks_run_as_usual_and_show_no_simulation_mode(harness, mode) -> None:
    _mode(harness, mode)
    run = harness.mdi("G1 X5 F6000")
    ch = run.channel
    assert ch.axes[0].position_mm == pytest.approx(5.0) and ch.errors.entries == ()
    assert ch.program.execution_mode_active == 0


def test_the_error_that_ends_a_check_is_listed_after_many_findings(harness) -> None:
    harness.home()  # the software limits count once the axes are referenced (P-AXIS-00705)
    _mode(harness, SYNCHK | MACHINE_LOCK)
    text = "".join(f"G1 X1 F100 Q{k}\n" for k in range(10)) + "G1 X5000\nM30\n"
    ch = harness.run(text, "a.nc").channel
    assert ch.state == ChannelState.ERROR and ch.errors.count == 11
    last = ch.errors.entries[-1]
    assert (last.id, last.line, last.warning) == (50101, 11, False)


def test_a_check_runs_while_the_axis_output_is_suspended() -> None:
    with KernelHarness() as h:
        ch = h.kernel.state.channels[0]  # suspended, as channel 2 of the default
        ch.suspend = replace(ch.suspend, output_suspended=True)
        _mode(h, SYNCHK | MACHINE_LOCK)
        run = h.run("G1 X1 F100 Q1\nM30\n", "a.nc")
        assert run.channel.state == ChannelState.READY
        assert [e.id for e in run.channel.errors.entries] == [21220]


def test_the_dry_run_ignores_feedhold(harness) -> None:
    _mode(harness, MACHINE_LOCK)
    harness.start(generate_program(60_000), "long.nc")
    assert harness.command(Feedhold(0, True)) is None
    run = harness.wait()
    assert run.channel.state == ChannelState.READY


def test_an_error_in_a_subprogram_shows_the_subprogram_at_the_pause(harness) -> None:
    harness.programs["sub.nc"] = "G1 X1 Q1\nM17\n"
    _mode(harness, SYNCHK | MACHINE_LOCK)
    _param(harness, "interactive", 1)
    harness.start("G1 X0 F100\nL sub.nc\nM30\n", "m.nc")
    ch = harness.wait_for(lambda s: s.channels[0].state == ChannelState.HOLD).channels[0]
    assert (ch.block.file_name, ch.block.line, ch.block.file_offset) == ("sub.nc", 1, 0)
    assert harness.command(ResetChannel(0, True)) is None


def test_a_log_over_the_store_limit_keeps_the_first_errors_and_the_count(harness) -> None:
    _mode(harness, SYNCHK | MACHINE_LOCK)
    _param(harness, "record_result", 1)
    text = "".join(f"N{k} G1 X1 F100 Q7\n" for k in range(1, 30001)) + "M30\n"
    run = harness.run(text, "many.nc")
    assert run.channel.errors.count == 30000
    data = harness.files["dec01.sc"]
    assert len(data) <= 1_000_000
    log = data.decode().splitlines()
    assert log[0] == "; syntax check of many.nc in channel 1"
    assert log[2].startswith("error 21220 (term) at many.nc:1:")  # the first error is kept
    assert log[-2].endswith("more errors are not listed (the output area's file limit)")
    assert log[-1] == "; end: 30001 lines, 30001 blocks, 30000 errors, complete"
