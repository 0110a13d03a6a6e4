"""Syntax-check mode of the decoder (ISG FCT-C9): every error is reported with its
category and decoding goes on with the response of that category (``nc/check.py``)."""

from __future__ import annotations

import dataclasses
from itertools import islice
from pathlib import Path

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from cnc_objects.service.kernel.nc import (
    AxisExchange,
    AxisExchangeKind,
    Block,
    Decoder,
    MotionKind,
    NcError,
    NcErrorId,
    StopKind,
    work_guard,
)
from cnc_objects.service.kernel.nc.check import CheckAborted, ErrorCategory, PointBatch
from tests.support.check_mode import Recorder, Run
from tests.support.nc_programs import nc_text, plain_programs

from .support import AXES, TOOLS, loader_of

MAX_ITEMS = 100_000  # a check that does not end is cut off here (and fails the test)

E = NcErrorId
C = ErrorCategory

EXAMPLE_PATH = Path(__file__).resolve().parents[4] / "docs" / "examples" / "check-syntax.nc"
# the example program of the function description (FCT-C9), character for character
SEED_EXAMPLE = EXAMPLE_PATH.read_text(encoding="utf-8")






def check_run(text: str, *, errors_per_block: int = 0, line_by_line: bool = False,
              files=None, file: str = "prog.nc", limit: int = MAX_ITEMS) -> Run:
    check = Recorder(errors_per_block, line_by_line)
    decoder = Decoder(text, file, axes=AXES, loader=loader_of(files), tools=TOOLS,
                      check=check)
    items = list(islice(decoder.blocks(), limit))
    assert len(items) < limit, "the check did not end"
    return Run(check, items, decoder)


def normal_blocks(text: str, files=None) -> list[Block]:
    decoder = Decoder(text, "prog.nc", axes=AXES, loader=loader_of(files), tools=TOOLS)
    return list(islice(decoder.blocks(), MAX_ITEMS))


def without_offset(block: Block) -> Block:
    return dataclasses.replace(block, source=dataclasses.replace(block.source, offset=0))


# ------------------------------------------------------------ the example program


def test_example_program_of_the_function_description() -> None:
    run = check_run(SEED_EXAMPLE)
    assert run.check.found == [
        (20113, 5, C.LIMIT),  # N40 F1111111111111111 overflows
        (20500, 8, C.COMMAND),  # N50 #COMMAND
        (20310, 11, C.ASSIGNMENT),  # N60 V.E.not_present =
        (20151, 14, C.COMMAND),  # N70 #CALL AX [X2, 11, 0]
        (20121, 17, C.COMBINATION),  # N80 G00 G01
    ]
    columns = [e.column for e, _ in run.check.errors]
    assert columns == [13, 5, 5, 19, 9]  # F, #, V, 11, G01
    assert all(e.file == "prog.nc" for e, _ in run.check.errors)
    assert run.ended()
    last = run.items[-1]
    assert (last.source.line, last.number) == (19, 130)
    n40 = [b for b in run.blocks if b.source.line == 5]
    assert len(n40) == 1 and n40[0].motion.end_mm == (10.0, 0.0, 0.0)
    assert n40[0].motion.kind == MotionKind.LINEAR  # the bad F is dropped, G01 used
    n80 = [b for b in run.blocks if b.source.line == 17]
    assert len(n80) == 1 and n80[0].number == 80
    assert n80[0].motion.kind == MotionKind.RAPID  # G00 G01: the first of the group wins
    assert n80[0].motion.end_mm == (100.0, 0.0, 0.0)
    # N50..N70 are dropped: nothing between N40 and N80 moves
    assert run.ends() == [(10.0, 0.0, 0.0), (100.0, 0.0, 0.0)]


def test_error_limit_of_the_caller_ends_decoding() -> None:
    check = Recorder(errors_total=3)
    decoder = Decoder(SEED_EXAMPLE, "prog.nc", axes=AXES, loader=loader_of(None),
                      tools=TOOLS, check=check)
    items = []
    try:
        for item in decoder.blocks():
            items.append(item)
    except CheckAborted:
        pass
    else:
        raise AssertionError("the check was not aborted")
    assert [f[0] for f in check.found] == [20113, 20500, 20310]
    assert not any(isinstance(b, Block) and b.source.line > 11 for b in items)


def test_example_program_step_by_step_gives_the_same_errors() -> None:
    run = check_run(SEED_EXAMPLE, line_by_line=True)
    assert [f[0] for f in run.check.found] == [20113, 20500, 20310, 20151, 20121]
    assert run.batches == [] and run.ended()


# ------------------------------------------------------------ the responses per category


def test_term_is_dropped_and_the_rest_of_the_line_used() -> None:
    run = check_run("G1 X10 Q5 Y3 F100\nG1 X20\nM30")
    assert run.check.found == [(int(E.UNKNOWN_WORD), 1, C.TERM)]
    assert run.check.errors[0][0].column == 8
    first = run.blocks[0]
    assert first.motion.end_mm == (10.0, 3.0, 0.0)
    assert first.motion.feed_mm_s * 60 == 100.0  # F after the bad term still used
    assert run.ends() == [(10.0, 3.0, 0.0), (20.0, 3.0, 0.0)]
    assert run.ended()


def test_unknown_g_and_missing_value_are_terms() -> None:
    run = check_run("G0 X1 G99 Y2\nG0 X3 Y\nM30")
    assert run.check.found == [(int(E.UNSUPPORTED_G_CODE), 1, C.TERM),
                               (int(E.MISSING_VALUE), 2, C.TERM)]
    assert run.ends() == [(1.0, 2.0, 0.0), (3.0, 2.0, 0.0)]


def test_error_inside_brackets_drops_the_whole_word() -> None:
    # the word X[...] is the term: Y5 and F100 behind it are used, no error cascade
    run = check_run("G1 X[1 +] Y5 F100\nG1 X[FOO[4]] Z2\nG1 X2\nM30")
    assert run.check.found == [(int(E.EXPRESSION_SYNTAX), 1, C.TERM),
                               (int(E.UNKNOWN_FUNCTION), 2, C.TERM)]
    assert run.ends() == [(0.0, 5.0, 0.0), (0.0, 5.0, 2.0), (2.0, 5.0, 2.0)]
    assert run.blocks[0].motion.feed_mm_s * 60 == 100.0


def test_unclosed_bracket_at_the_end_of_the_line_drops_only_its_word() -> None:
    run = check_run("G1 X5 F100 Y[2*[3+1]\nM30")
    assert run.check.found == [(int(E.EXPRESSION_SYNTAX), 1, C.TERM)]
    assert run.ends() == [(5.0, 0.0, 0.0)]


def test_assignment_with_bad_left_side_is_dropped_and_the_rest_runs() -> None:
    run = check_run("V.E.NOPE = 1 G0 X5\nV.L.NOPE = 2 G0 Y7\nM30")
    assert run.check.found == [(int(E.UNKNOWN_VARIABLE), 1, C.ASSIGNMENT),
                               (int(E.UNDECLARED_VARIABLE), 2, C.ASSIGNMENT)]
    assert [e.column for e, _ in run.check.errors] == [1, 1]
    assert run.ends() == [(5.0, 0.0, 0.0), (5.0, 7.0, 0.0)]


def test_assignment_with_bad_index_is_dropped_and_the_next_one_runs() -> None:
    text = ("#VAR\nV.L.A[2] = [0, 0]\nV.L.B = 0\n#ENDVAR\n"
            "V.L.A[5] = 3 V.L.B = 4 G0 X1\nG0 X[V.L.B]\nM30")
    run = check_run(text)
    assert run.check.found == [(int(E.ARRAY_INDEX_OUT_OF_RANGE), 5, C.ASSIGNMENT)]
    assert run.ends() == [(1.0, 0.0, 0.0), (4.0, 0.0, 0.0)]


def test_error_in_the_right_side_of_an_assignment_drops_only_the_assignment() -> None:
    text = "#VAR\nV.L.A = 7\n#ENDVAR\nV.L.A = 1/0 G0 X[V.L.A]\nM30"
    run = check_run(text)
    assert run.check.found == [(int(E.DIVISION_BY_ZERO), 4, C.VALUE)]
    assert run.ends() == [(7.0, 0.0, 0.0)]


def test_junk_after_an_axis_command_uses_the_command() -> None:
    run = check_run("G0 X1 Y1\n#AX RELEASE [Y] X10\nG0 X2\nM30")
    assert run.check.found == [(int(E.AXIS_COMMAND_NOT_ALONE), 2, C.AFTER_COMMAND)]
    assert run.check.errors[0][0].column == 17
    release = [b for b in run.blocks if b.axis_exchange is not None]
    assert [b.axis_exchange for b in release] == [AxisExchange(AxisExchangeKind.RELEASE, (1,))]
    assert run.decoder.modal.released_axes == frozenset({1})
    assert run.ends() == [(1.0, 1.0, 0.0), (2.0, 1.0, 0.0)]  # X10 was not used
    assert run.ended()


def test_junk_after_a_control_statement_uses_the_statement() -> None:
    run = check_run("$IF 1 junk\nG0 X1\n$ENDIF junk\nG0 X2\n$IF 0 junk\nG0 X3\n$ENDIF\nM30")
    assert run.check.found == [(int(E.UNKNOWN_WORD), 1, C.AFTER_COMMAND),
                               (int(E.UNKNOWN_WORD), 3, C.AFTER_COMMAND),
                               (int(E.UNKNOWN_WORD), 5, C.AFTER_COMMAND)]
    assert run.ends() == [(1.0, 0.0, 0.0), (2.0, 0.0, 0.0)]  # $IF 0 skipped its block
    assert run.ended()


def test_error_in_a_command_drops_the_line() -> None:
    run = check_run("N50 #COMMAND UNKNOWN [...] X5\nG0 X1\n#AX REQUEST [Y\nG0 Y2\nM30")
    assert run.check.found == [(int(E.INSTRUCTION_NOT_SUPPORTED), 1, C.COMMAND),
                               (int(E.EXPRESSION_SYNTAX), 3, C.COMMAND)]
    assert run.ends() == [(1.0, 0.0, 0.0), (1.0, 2.0, 0.0)]
    assert all(b.axis_exchange is None for b in run.blocks)


def test_combination_drops_the_second_word() -> None:
    run = check_run("G0 X1 X2 Y3\nG1 G2 X4 F100\nM0 M30 X5\nG0 X6\nM30")
    assert run.check.found == [(int(E.WORD_REPEATED), 1, C.COMBINATION),
                               (int(E.CONFLICTING_G_CODES), 2, C.COMBINATION),
                               (int(E.CONFLICTING_M_CODES), 3, C.COMBINATION)]
    assert run.ends() == [(1.0, 3.0, 0.0), (4.0, 3.0, 0.0), (5.0, 3.0, 0.0), (6.0, 3.0, 0.0)]
    assert run.blocks[1].motion.kind == MotionKind.LINEAR
    stops = [b.stop for b in run.blocks if b.source.line == 3]
    assert stops == [StopKind.PROGRAMMED]  # M30 dropped: decoding goes on after line 3
    assert run.ended()


def test_value_errors_drop_the_word() -> None:
    run = check_run("G1 X5 F-5 Y2\nG1 X7\nG0 X8 S-5 D9 Z1\nM30")
    assert sorted(run.check.found) == [(int(E.INVALID_FEED), 1, C.VALUE),
                                       (int(E.INVALID_SPINDLE_SPEED), 3, C.VALUE),
                                       (int(E.TOOL_NOT_IN_TABLE), 3, C.VALUE)]
    # the bad F leaves the feed unknown: no "no feed" for the G1 lines after it
    assert run.ends() == [(5.0, 2.0, 0.0), (7.0, 2.0, 0.0), (8.0, 2.0, 1.0)]


def test_value_error_inside_a_word_drops_that_word() -> None:
    run = check_run("G1 X[1/0] Y5 F100\nG1 X2\nG1 X3 F[1/0]\nG1 X4\nM30")
    assert run.check.found == [(int(E.DIVISION_BY_ZERO), 1, C.VALUE),
                               (int(E.DIVISION_BY_ZERO), 3, C.VALUE)]
    assert run.ends() == [(0.0, 5.0, 0.0), (2.0, 5.0, 0.0), (3.0, 5.0, 0.0), (4.0, 5.0, 0.0)]
    assert run.blocks[0].motion.feed_mm_s * 60 == 100.0


def test_limit_errors_drop_the_word() -> None:
    run = check_run("G1 X10 F1111111111111111 Y2\nG1 X3\n/12 G0 X9\nG0 Z4\nM30")
    assert run.check.found == [(int(E.VALUE_OUT_OF_RANGE), 1, C.LIMIT),
                               (int(E.INVALID_SKIP_LEVEL), 3, C.LIMIT)]
    assert run.ends()[:2] == [(10.0, 2.0, 0.0), (3.0, 2.0, 0.0)]
    assert run.ends()[-1][2] == 4.0
    assert run.ended()


def test_missing_feed_is_reported_once() -> None:
    run = check_run("G1 X1\nG1 X2\nG1 X3 Y1\nG2 X5 Y3 I2\nM30")
    assert run.check.found == [(int(E.NO_FEED), 1, C.INCOMPLETE)]
    assert run.ends() == [(1.0, 0.0, 0.0), (2.0, 0.0, 0.0), (3.0, 1.0, 0.0), (5.0, 3.0, 0.0)]
    assert run.ended()


def test_missing_file_drops_the_call_and_decoding_goes_on() -> None:
    run = check_run("L nofile\nG0 X4\nLL nosub\nG0 X5\nM30")
    assert run.check.found == [(int(E.FILE_NOT_FOUND), 1, C.RESOURCE),
                               (int(E.SUBPROGRAM_NOT_FOUND), 3, C.RESOURCE)]
    assert run.ends() == [(4.0, 0.0, 0.0), (5.0, 0.0, 0.0)]
    assert len(run.decoder.frames) == 1 and run.ended()


def test_failing_call_keeps_the_motion_of_its_line() -> None:
    # the words ran (the position moved to X3): their Block is not lost
    run = check_run("G0 X3 L nofile\nG1 Y4 F100\nG0 X6 $GOTO N99\nM30")
    assert run.check.found == [(int(E.FILE_NOT_FOUND), 1, C.RESOURCE),
                               (int(E.LABEL_NOT_FOUND), 3, C.INCOMPLETE)]
    assert run.ends() == [(3.0, 0.0, 0.0), (3.0, 4.0, 0.0), (6.0, 4.0, 0.0)]


def test_errors_in_a_subprogram_name_the_subprogram() -> None:
    files = {"sub.nc": "G0 X1 Q2\nG0 X2 Y3\nM17"}
    run = check_run("L sub.nc\nG0 X9\nM30", files=files)
    assert [(e.file, e.line, cat) for e, cat in run.check.errors] == [("sub.nc", 1, C.TERM)]
    assert run.ends() == [(1.0, 0.0, 0.0), (2.0, 3.0, 0.0), (9.0, 3.0, 0.0)]


def test_subprogram_end_in_the_main_program_keeps_the_block() -> None:
    run = check_run("G0 X1 M17\nG0 X9\nM30")
    assert run.check.found == [(int(E.SUBPROGRAM_END_IN_MAIN), 1, C.COMBINATION)]
    assert run.ends() == [(1.0, 0.0, 0.0), (9.0, 0.0, 0.0)]
    assert run.ended()


def test_arc_error_stays_in_its_line() -> None:
    run = check_run("G1 X10 F100\nG2 X20 Y0 I3 J4\nG1 Y5\nM30")
    assert run.check.found[0] == (int(E.ARC_RADIUS_DIFFERENCE), 2, C.VALUE)
    assert {line for _, line, _ in run.check.found} == {2}  # nothing after line 2
    assert run.end_of_line(3)[1:] == (5.0, 0.0)
    assert run.ended()


# ------------------------------------------------------------ errors per block


def test_errors_per_block_limits_the_errors_of_a_line() -> None:
    text = "G0 X1 Q1 Q2 Q3 Y4\nG0 X2\nM30"
    limited = check_run(text, errors_per_block=2)
    assert limited.check.found == [(int(E.UNKNOWN_WORD), 1, C.TERM)] * 2
    assert [e.column for e, _ in limited.check.errors] == [7, 10]
    assert limited.end_of_line(1) is None  # the rest of the line is dropped
    assert limited.ends() == [(2.0, 0.0, 0.0)]
    assert limited.ended()

    unlimited = check_run(text, errors_per_block=0)
    assert [e.column for e, _ in unlimited.check.errors] == [7, 10, 13]
    assert unlimited.ends() == [(1.0, 4.0, 0.0), (2.0, 4.0, 0.0)]


def test_errors_per_block_counts_parse_and_execution_errors_together() -> None:
    text = "G0 Q1 X1 G1 Y3 S-5\nG0 X2\nM30"
    limited = check_run(text, errors_per_block=2)
    assert limited.check.found == [(int(E.UNKNOWN_WORD), 1, C.TERM),
                                   (int(E.CONFLICTING_G_CODES), 1, C.COMBINATION)]
    assert limited.ends() == [(2.0, 0.0, 0.0)]
    three = check_run(text, errors_per_block=3)  # the third error reaches the limit
    assert len(three.check.found) == 3
    assert three.ends() == [(2.0, 0.0, 0.0)]
    four = check_run(text, errors_per_block=4)
    assert [f[0] for f in four.check.found] == [
        int(E.UNKNOWN_WORD), int(E.CONFLICTING_G_CODES), int(E.INVALID_SPINDLE_SPEED)]
    assert four.ends() == [(1.0, 3.0, 0.0), (2.0, 3.0, 0.0)]


def test_one_error_per_block_drops_the_line_at_the_first_error() -> None:
    run = check_run("G0 X1 G1 Y2\nG0 X3\nM30", errors_per_block=1)
    assert run.check.found == [(int(E.CONFLICTING_G_CODES), 1, C.COMBINATION)]
    assert run.ends() == [(3.0, 0.0, 0.0)]


def test_one_error_per_block_drops_a_command_with_junk_after_it() -> None:
    run = check_run("#AX RELEASE [Y] X10\nG0 Y2\nM30", errors_per_block=1)
    assert run.check.found == [(int(E.AXIS_COMMAND_NOT_ALONE), 1, C.AFTER_COMMAND)]
    assert run.decoder.modal.released_axes == frozenset()
    assert run.ends() == [(0.0, 2.0, 0.0)]


def test_one_error_per_block_drops_the_call_of_the_line() -> None:
    files = {"sub.nc": "G0 Z7\nM17"}
    run = check_run("G0 G1 X1 L sub.nc\nG0 X3\nM30", errors_per_block=1, files=files)
    assert run.check.found == [(int(E.CONFLICTING_G_CODES), 1, C.COMBINATION)]
    assert run.ends() == [(3.0, 0.0, 0.0)]  # sub.nc did not run


# ------------------------------------------------------------ control statements


def test_failing_if_condition_skips_the_whole_if_block() -> None:
    text = ("$IF V.L.NOPE == 1\nG0 X1\n$ELSE\nG0 X2\n$ENDIF\nG0 X5\n"
            "$IF [1 +] == 2\nG0 Y1\n$ENDIF\nG0 Y5\nM30")
    run = check_run(text)
    assert run.check.found == [(int(E.UNDECLARED_VARIABLE), 1, C.COMMAND),
                               (int(E.EXPRESSION_SYNTAX), 7, C.COMMAND)]
    assert run.ends() == [(5.0, 0.0, 0.0), (5.0, 5.0, 0.0)]
    assert run.ended()


def test_failing_loop_and_switch_heads_skip_their_blocks() -> None:
    text = ("$WHILE V.L.NOPE < 3\nG0 X1\n$ENDWHILE\n"
            "$WHILE FOO[1]\nG0 X2\n$ENDWHILE\n"
            "$FOR V.L.NOPE = 0, 3, 1\nG0 X3\n$ENDFOR\n"
            "$SWITCH V.L.NOPE\n$CASE 1\nG0 X4\n$BREAK\n$ENDSWITCH\n"
            "G0 X9\nM30")
    run = check_run(text)
    assert [f[:2] for f in run.check.found] == [
        (int(E.UNDECLARED_VARIABLE), 1), (int(E.UNKNOWN_FUNCTION), 4),
        (int(E.UNDECLARED_VARIABLE), 7), (int(E.UNDECLARED_VARIABLE), 10)]
    assert run.ends() == [(9.0, 0.0, 0.0)]
    assert run.ended()


def test_broken_elseif_or_case_skips_the_block_without_a_decoder_fault() -> None:
    text = ("$IF 0\nG0 X1\n$ELSEIF [1 +\nG0 X2\n$ELSE\nG0 X3\n$ENDIF\n"
            "$IF 1\nG0 Y1\n$ELSEIF [1 +\nG0 Y2\n$ENDIF\n"
            "$SWITCH 2\n$CASE [1 +\nG0 Z1\n$BREAK\n$CASE 2\nG0 Z2\n$BREAK\n$ENDSWITCH\n"
            "G0 X9\nM30")
    run = check_run(text)
    assert run.check.found == [(int(E.EXPRESSION_SYNTAX), 3, C.COMMAND),
                               (int(E.EXPRESSION_SYNTAX), 10, C.COMMAND),
                               (int(E.EXPRESSION_SYNTAX), 14, C.COMMAND)]
    # the failing $IF 0 skips its block; $IF 1 runs its branch and ends at the $ELSEIF
    assert run.ends() == [(0.0, 1.0, 0.0), (9.0, 1.0, 0.0)]
    assert run.ended()


def test_failing_until_ends_its_loop() -> None:
    text = "$IF 1\n$REPEAT\nG0 X1\n$UNTIL V.L.NOPE == 1\n$ENDIF\nG0 X5\nM30"
    run = check_run(text)
    assert run.check.found == [(int(E.UNDECLARED_VARIABLE), 4, C.COMMAND)]
    assert run.ends() == [(1.0, 0.0, 0.0), (5.0, 0.0, 0.0)]
    assert run.ended()


def test_endif_without_if_is_reported_once() -> None:
    run = check_run("G0 X1\n$ENDIF\nG0 X2\n$ENDFOR\nG0 X3\nM30")
    assert run.check.found == [(int(E.ENDIF_WITHOUT_IF), 2, C.COMMAND),
                               (int(E.LOOP_END_WITHOUT_BEGIN), 4, C.COMMAND)]
    assert run.ends() == [(1.0, 0.0, 0.0), (2.0, 0.0, 0.0), (3.0, 0.0, 0.0)]
    assert run.ended()


def test_missing_program_end_is_reported_and_decoding_ends() -> None:
    run = check_run("G0 X1\nG0 X2\n")
    assert run.check.found == [(int(E.MISSING_PROGRAM_END), 2, C.INCOMPLETE)]
    assert run.ends() == [(1.0, 0.0, 0.0), (2.0, 0.0, 0.0)]
    assert not run.ended() and run.decoder.finished


def test_unclosed_if_and_missing_end_are_both_reported() -> None:
    run = check_run("$IF 1\nG0 X1")
    assert run.check.found == [(int(E.BLOCK_NOT_CLOSED), 1, C.INCOMPLETE),
                               (int(E.MISSING_PROGRAM_END), 2, C.INCOMPLETE)]
    assert run.decoder.finished


def test_endless_loop_is_reported_not_hung(monkeypatch) -> None:
    monkeypatch.setattr(work_guard, "IDLE_STEPS_MAX", 1000)
    run = check_run("$WHILE 1\n; only a comment\n$ENDWHILE\nG0 X1\nM30", limit=20_000)
    # reported once, at the loop's line the decoder stands at; the check ends there
    # (nothing after an endless program runs)
    [(err, line, category)] = run.check.found
    assert (err, category) == (int(E.ENDLESS_LOOP), C.RESOURCE) and line in (1, 2, 3)
    assert run.ends() == [] and not run.ended() and run.decoder.finished


# ------------------------------------------------------------ assignments run once


def test_assignments_before_an_error_run_once() -> None:
    text = ("#VAR\nV.L.A = 0\n#ENDVAR\n"
            "V.L.A = V.L.A + 1 G0 G1 X1\n"
            "G0 X[V.L.A * 10]\nM30")
    run = check_run(text)
    assert run.check.found == [(int(E.CONFLICTING_G_CODES), 4, C.COMBINATION)]
    assert run.ends() == [(1.0, 0.0, 0.0), (10.0, 0.0, 0.0)]


def test_assignments_around_several_errors_run_once() -> None:
    text = ("#VAR\nV.L.A = 0\n#ENDVAR\n"
            "V.L.A = V.L.A + 1 G0 X1 Q1 V.L.A = V.L.A + 10 Y2 G1 S-1 V.L.A = V.L.A + 100\n"
            "G0 X[V.L.A]\nM30")
    run = check_run(text)
    assert [f[0] for f in run.check.found] == [
        int(E.UNKNOWN_WORD), int(E.CONFLICTING_G_CODES), int(E.INVALID_SPINDLE_SPEED)]
    assert run.ends() == [(1.0, 2.0, 0.0), (111.0, 2.0, 0.0)]


def test_assignment_in_a_loop_with_an_error_runs_once_per_pass() -> None:
    text = ("#VAR\nV.L.A = 0\nV.L.I = 0\n#ENDVAR\n"
            "$WHILE V.L.I < 3\n"
            "V.L.I = V.L.I + 1 V.L.A = V.L.A + 2 G0 G1 X[V.L.A]\n"
            "$ENDWHILE\nG0 Y[V.L.A]\nM30")
    run = check_run(text)
    assert run.check.found == [(int(E.CONFLICTING_G_CODES), 6, C.COMBINATION)] * 3
    assert run.ends() == [(2.0, 0.0, 0.0), (4.0, 0.0, 0.0), (6.0, 0.0, 0.0), (6.0, 6.0, 0.0)]


# ------------------------------------------------------------ PointBatch records


def _bench_program(lines: int = 2000) -> str:
    from bench.decoder_bench import generate_program

    return generate_program(lines)


def _normal_points(text: str) -> list:
    return [("prog.nc", b.source.line, b.motion.kind, b.motion.end_mm, b.motion.center_mm)
            for b in normal_blocks(text) if b.motion is not None]


def test_point_batches_give_the_motions_of_a_normal_run() -> None:
    text = _bench_program()
    expected = _normal_points(text)
    run = check_run(text)
    assert run.check.errors == []
    assert run.ended()
    assert run.points() == expected  # line, kind, end point, centre: block by block
    assert len(expected) > 1500
    records = [r for batch in run.batches for r in batch.records]
    assert len(records) > len(expected) // 2  # most lines took the hot path
    assert any(r[3] is not None for r in records)  # arcs with their centres
    assert any(r[3] is None for r in records)  # straight lines without one


def test_point_batches_chain_their_start_points() -> None:
    text = _bench_program()
    run = check_run(text)
    position = (0.0, 0.0, 0.0)
    for item in run.items:
        if isinstance(item, PointBatch):
            assert item.start_mm == position
            for index, kind, end, centre in item.records:
                assert item.first <= index < item.stop
                if centre is not None:
                    assert kind in (MotionKind.ARC_CW, MotionKind.ARC_CCW)
                    assert item.plane == (0, 1)
                position = end
        elif item.motion is not None:
            assert item.motion.start_mm == position
            position = item.motion.end_mm


def test_every_line_is_decoded_once_by_a_batch_or_by_line() -> None:
    text = _bench_program()
    run = check_run(text)
    spans = sorted([(b.first, b.stop) for b in run.batches]
                   + [(index, after) for _, index, after in run.check.lines])
    assert spans[0][0] == 1  # after the %BENCH header
    for (_, stop), (start, _) in zip(spans, spans[1:]):
        assert stop == start  # no gap, no line twice
    assert spans[-1][1] == text.count("\n")  # up to the M30 line
    assert {file for file, _, _ in run.check.lines} == {"prog.nc"}


def test_line_by_line_sends_every_line_through_line() -> None:
    text = _bench_program(600)
    run = check_run(text, line_by_line=True)
    assert run.batches == []
    indices = [(index, after) for _, index, after in run.check.lines]
    assert indices == [(k, k + 1) for k in range(1, text.count("\n"))]
    normal = [without_offset(b) for b in normal_blocks(text)]
    assert [without_offset(b) for b in run.blocks] == normal
    assert run.check.errors == []


def test_batches_are_bounded() -> None:
    from cnc_objects.service.kernel.nc.check import BATCH_LINES

    text = "G1 F100\n" + "\n".join(f"G1 X{k % 97}.5 Y{k % 13}" for k in range(5000)) + "\nM30"
    run = check_run(text)
    assert run.check.errors == []
    assert all(b.stop - b.first <= BATCH_LINES for b in run.batches)
    assert len(run.ends()) == 5000


def test_tool_radius_compensation_takes_the_general_path() -> None:
    text = "G1 X0 Y0 F100\nG41 D1\nG1 X10\nG1 Y10\nG40\nG1 X0\nG1 Y0\nM30"
    run = check_run(text)
    assert run.check.errors == []
    assert {b.source.line for b in run.blocks if b.motion is not None} >= {3, 4}
    assert all(r[0] not in (2, 3) for b in run.batches for r in b.records)
    assert run.ends() == [(10.0, 0.0, 0.0), (10.0, 10.0, 0.0), (0.0, 10.0, 0.0),
                          (0.0, 0.0, 0.0)]


# ------------------------------------------------------------ clean programs


CLEAN_PROGRAM = """\
%MAIN
; a clean program with the general path's statements
#VAR
V.L.I = 0
V.L.ARR[3] = [1, 2, 3]
#ENDVAR
N10 G17 G90 G0 X0 Y0 Z5
N20 G1 Z-1 F500
$FOR V.L.I = 0, 2, 1
  G1 X[V.L.ARR[V.L.I] * 10] Y[V.L.I]
$ENDFOR
$IF V.L.I == 3
  G2 X40 Y0 I5 J-1
$ELSE
  G0 Z50
$ENDIF
$SWITCH V.L.I
$CASE 3
  LL SIDE
  $BREAK
$DEFAULT
  G0 Z60
$ENDSWITCH
L sub.nc
N90 M30
%L SIDE
G1 Y-10
M17
"""


def test_clean_program_reports_no_errors() -> None:
    files = {"sub.nc": "G91 G1 X1 Y1\nG90\nM17\n"}
    run = check_run(CLEAN_PROGRAM, files=files)
    assert run.check.errors == []
    assert run.ended()
    normal = [b for b in normal_blocks(CLEAN_PROGRAM, files) if b.motion is not None]
    assert run.ends() == [b.motion.end_mm for b in normal]
    assert run.ends()[-1] == (41.0, -9.0, -1.0)


def test_clean_bench_program_reports_no_errors_line_by_line() -> None:
    run = check_run(_bench_program(1000), line_by_line=True, errors_per_block=1)
    assert run.check.errors == [] and run.ended()


# ------------------------------------------------------------ properties

_BASE = [
    "%P",
    "N1 G0 X0 Y0 Z5",
    "N2 G1 X1 Y2 Z-1 F500",
    "N3 G1 X10.5 Y5.5 Z1.5 F800",
    "N4 G1 X12.25 Y-3.25 Z0.25 F1200",
    "N5 G0 X-4.75 Y7.75 Z2.75",
    "N6 G1 X1.125 Y1.875 Z3.125 F900",
    "N7 M30",
]
_JUNK = [
    "Q5", "X", "X[", "]", "[", "1.2.3", "X1.2.3", "G99", "G2", "F-5", "F0", "S-1", "D7",
    "I5", "R3", "X1e400", "V.L.NOPE", "V.L.NOPE = 1", "V.E.NOPE = 2", "=", "ß", "M17",
    "M3.5", "L nofile", "LL nosub", "$GOTO N99", "$IF", "$ENDIF", "$WHILE", "$ELSE", "$CASE",
    "$BREAK", "#FOO", "X[1/0]", "F[1/0]", "X[V.L.NOPE]", "X[SIN[", '"s"', "(", ";", "N5",
    ":", "*", "G4", "T-1", "N-1",
]


@st.composite
def junk_programs(draw):
    """(text, 1-based number of the line with junk) from ``_BASE``."""
    line_no = draw(st.integers(2, len(_BASE) - 1))  # a motion line, not the header or M30
    words = _BASE[line_no - 1].split()
    for junk in draw(st.lists(st.sampled_from(_JUNK), min_size=1, max_size=3)):
        words.insert(draw(st.integers(0, len(words))), junk)
    lines = list(_BASE)
    lines[line_no - 1] = " ".join(words)
    return "\n".join(lines) + "\n", line_no


_CLEAN_ENDS = {b.source.line: b.motion.end_mm
               for b in normal_blocks("\n".join(_BASE) + "\n") if b.motion is not None}


@settings(max_examples=300, deadline=None)
@given(program=junk_programs(), errors_per_block=st.integers(0, 3),
       line_by_line=st.booleans())
def test_junk_in_one_line_is_reported_in_that_line_only(program, errors_per_block,
                                                       line_by_line) -> None:
    text, junk_line = program
    run = check_run(text, errors_per_block=errors_per_block, line_by_line=line_by_line)
    lines = text.split("\n")
    for error, _category in run.check.errors:
        assert error.id != E.INTERNAL_ERROR, str(error)
        assert error.line == junk_line, str(error)
        assert 1 <= error.column <= len(lines[error.line - 1]) + 1, str(error)
    if errors_per_block:
        assert len(run.check.errors) <= errors_per_block
    assert run.ended()
    for line, end in _CLEAN_ENDS.items():
        if line != junk_line:
            assert run.end_of_line(line) == end, line


def _normal_outcome(text: str, files, limit: int = 300):
    """(blocks, error or None) of a normal run, cut off after ``limit`` blocks."""
    decoder = Decoder(text, "prog.nc", axes=AXES, loader=loader_of(files), tools=TOOLS)
    blocks = []
    try:
        blocks.extend(islice(decoder.blocks(), limit))
    except NcError as error:
        return blocks, error
    return blocks, None


@settings(max_examples=300, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(text=st.one_of(
    nc_text, plain_programs().map(lambda lines: "\n".join(["F1000", *lines, "M30"]))))
def test_check_reports_first_what_a_normal_run_stops_at(monkeypatch, text) -> None:
    """Up to the first error the check decodes what a normal run does; its first report
    is the error the normal run raises; a program without error reports nothing."""
    monkeypatch.setattr(work_guard, "IDLE_STEPS_MAX", 200)
    files = {"s.nc": text}
    blocks, error = _normal_outcome(text, files)
    # the error limit ends recursive programs, which go on after each error
    check = Recorder(errors_total=100)
    decoder = Decoder(text, "prog.nc", axes=AXES, loader=loader_of(files), tools=TOOLS,
                      check=check)
    run = Run(check, [], decoder)
    try:
        for item in islice(decoder.blocks(), 3000):
            run.items.append(item)
    except CheckAborted:
        assert len(check.errors) == 100
    assert all(e.id != E.INTERNAL_ERROR for e, _ in check.errors), check.errors
    expected = [(b.source.file, b.source.line, b.motion.end_mm)
                for b in blocks if b.motion is not None]
    assert [(p[0], p[1], p[3]) for p in run.points()][:len(expected)] == expected
    if error is not None:
        assert check.errors, str(error)
        first = check.errors[0][0]
        assert (first.id, first.file, first.line, first.column) == (
            error.id, error.file, error.line, error.column), (str(error), str(first))
    elif len(blocks) < 300:
        assert check.errors == []


def test_comment_end_without_begin_is_a_command_error() -> None:
    run = check_run("G1 X1 F100\n#COMMENT END\nG1 X2\nM30\n")
    assert [(e.id, e.line, c) for e, c in run.check.errors] == [
        (NcErrorId.COMMENT_END_WITHOUT_BEGIN, 2, ErrorCategory.COMMAND)]
