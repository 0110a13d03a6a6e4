"""Control flow at decode time: $IF, loops, $SWITCH, $GOTO, #RT WHILE, loop guard."""

from __future__ import annotations

from itertools import islice

import pytest

from cnc_objects.service.kernel.nc import NcErrorId, work_guard

from .support import decoder, ends, error_of

DECL = "#VAR\nV.L.I = 0\nV.L.J = 0\n#ENDVAR\n"


def xs(program: str, **kw) -> list[float]:
    """X of every motion end point (a first move to X-100 makes X0 a motion too)."""
    return [e[0] for e in ends("G0 X-100\n" + program, **kw)][1:]


@pytest.mark.parametrize(
    ("program", "expected"),
    [
        ("$IF 1\nG0 X1\n$ENDIF\nM30", [1]),
        ("$IF 0\nG0 X1\n$ENDIF\nG0 X2\nM30", [2]),
        ("$IF 0\nG0 X1\n$ELSE\nG0 X2\n$ENDIF\nM30", [2]),
        ("$IF 0\nG0 X1\n$ELSEIF 1\nG0 X2\n$ELSE\nG0 X3\n$ENDIF\nM30", [2]),
        ("$IF 0\nG0 X1\n$ELSEIF 0\nG0 X2\n$ELSE\nG0 X3\n$ENDIF\nM30", [3]),
        ("$IF 1\nG0 X1\n$ELSEIF 1\nG0 X2\n$ELSE\nG0 X3\n$ENDIF\nG0 X4\nM30", [1, 4]),
        ("$IF 1\n$IF 0\nG0 X1\n$ELSE\nG0 X2\n$ENDIF\n$ELSE\nG0 X3\n$ENDIF\nM30", [2]),
        ("$IF 0\n$IF 1\nG0 X1\n$ENDIF\n$WHILE 1\n$ENDWHILE\n$ELSE\nG0 X3\n$ENDIF\nM30", [3]),
        ("N10 $IF 1\nG0 X1\nN20 $ENDIF\nM30", [1]),
    ],
)
def test_if(program, expected) -> None:
    assert xs(program) == expected


@pytest.mark.parametrize(
    ("program", "expected"),
    [
        (DECL + "$WHILE V.L.I < 3\nG0 X[V.L.I]\nV.L.I = V.L.I + 1\n$ENDWHILE\nM30", [0, 1, 2]),
        ("$FOR V.P.K = 1, 3\nG0 X[V.P.K]\n$ENDFOR\nM30", [1, 2, 3]),
        ("$FOR V.P.K = 3, 1, -1\nG0 X[V.P.K]\n$ENDFOR\nM30", [3, 2, 1]),
        ("$FOR V.P.K = 0, 1, 0.5\nG0 X[V.P.K]\n$ENDFOR\nM30", [0, 0.5, 1]),
        ("$FOR V.P.K = 5, 1\nG0 X[V.P.K]\n$ENDFOR\nG0 X9\nM30", [9]),
        (DECL + "$REPEAT\nV.L.I = V.L.I + 1\nG0 X[V.L.I]\n$UNTIL V.L.I >= 2\nM30", [1, 2]),
        # nested loops
        ("$FOR V.P.K = 1, 2\n$FOR V.P.M = 1, 2\nG0 X[V.P.K * 10 + V.P.M]\n$ENDFOR\n$ENDFOR\nM30",
         [11, 12, 21, 22]),
        # $BREAK and $CONTINUE
        ("$FOR V.P.K = 1, 5\n$IF V.P.K == 3\n$BREAK\n$ENDIF\nG0 X[V.P.K]\n$ENDFOR\nM30", [1, 2]),
        ("$FOR V.P.K = 1, 4\n$IF V.P.K == 2\n$CONTINUE\n$ENDIF\nG0 X[V.P.K]\n$ENDFOR\nM30",
         [1, 3, 4]),
        (DECL + "$WHILE 1\nV.L.I = V.L.I + 1\n$IF V.L.I > 2\n$BREAK\n$ENDIF\nG0 X[V.L.I]\n"
         "$ENDWHILE\nM30", [1, 2]),
        # #RT WHILE: unrolled, the condition is evaluated at decode time
        (DECL + "#RT WHILE [V.L.I < 2]\nG0 X[V.L.I]\nV.L.I = V.L.I + 1\n#RT ENDWHILE\nM30", [0, 1]),
    ],
)
def test_loops(program, expected) -> None:
    decl = "#VAR\nV.P.K\nV.P.M\n#ENDVAR\n"
    assert xs(decl + program) == expected


@pytest.mark.parametrize(
    ("value", "expected"),
    [(0, [10, 11]), (1, [11]), (2, [20]), (3, [20]), (7, [99]), ('"s"', [30])],
)
def test_switch(value, expected) -> None:
    program = f"""$SWITCH {value}
$CASE 0
  G0 X10
$CASE 1
  G0 X11
  $BREAK
$CASE 2, 3
  G0 X20
  $BREAK
$CASE "s"
  G0 X30
  $BREAK
$DEFAULT
  G0 X99
$ENDSWITCH
M30"""
    assert xs(program) == expected


def test_switch_without_match_and_default() -> None:
    assert xs("$SWITCH 5\n$CASE 1\nG0 X1\n$ENDSWITCH\nG0 X2\nM30") == [2]


@pytest.mark.parametrize(
    ("program", "expected"),
    [
        ("$GOTO N30\nG0 X1\nN30: G0 X3\nM30", [3]),
        ("$GOTO [END]\nG0 X1\n[END] G0 X3\nM30", [3]),
        ("$GOTO [END]\nG0 X1\n[END]\nG0 X3\nM30", [3]),
        ("G0 X1 $GOTO N30\nG0 X2\nN30: G0 X3\nM30", [1, 3]),  # the jump comes last
        (DECL + "N10: V.L.I = V.L.I + 1\nG0 X[V.L.I]\n$IF V.L.I < 3 $GOTO N10\nM30", [1, 2, 3]),
        # jump out of a loop
        ("$WHILE 1\nG0 X1\n$GOTO [OUT]\n$ENDWHILE\n[OUT] G0 X2\nM30", [1, 2]),
        # jump from outside into an $IF branch (ISG allows it)
        ("$GOTO [IN]\n$IF 0\nG0 X1\n[IN] G0 X2\n$ELSE\nG0 X3\n$ENDIF\nG0 X4\nM30", [2, 4]),
        # the next label after the jump wins when a label is defined twice
        ("N20: G0 X1\n$IF 0 $GOTO N20\n$GOTO N20\nG0 X5\nN20: G0 X2\nM30", [1, 2]),
    ],
)
def test_goto(program, expected) -> None:
    assert xs(program) == expected


def test_while_with_motion_is_lazy() -> None:
    blocks = decoder("G1 F100\n$WHILE 1\nG1 X1\nG1 X0\n$ENDWHILE\nM30").blocks()
    taken = list(islice(blocks, 1001))
    assert len(taken) == 1001


def test_rt_while_without_condition_runs_as_long_as_pulled() -> None:
    blocks = decoder("G1 F100\n#RT WHILE\nG1 X1\nG1 X0\n#RT ENDWHILE\nM30").blocks()
    assert [b.motion.end_mm[0] for b in islice(blocks, 4)] == [1, 0, 1, 0]


def test_endless_loop_without_blocks_is_an_error(monkeypatch) -> None:
    monkeypatch.setattr(work_guard, "IDLE_STEPS_MAX", 1000)
    # the error is at the line the decoder stands at when the guard's limit is passed
    e = error_of("G0 X1\n$WHILE TRUE\n$ENDWHILE\nM30")
    assert (e.id, e.column) == (NcErrorId.ENDLESS_LOOP, 1) and e.line in (2, 3)
    e = error_of("N10: $GOTO N10\nM30")
    assert (e.id, e.line) == (NcErrorId.ENDLESS_LOOP, 1)


def test_loop_guard_counts_passes_without_blocks_only(monkeypatch) -> None:
    monkeypatch.setattr(work_guard, "IDLE_STEPS_MAX", 10)
    program = "#VAR\nV.L.I = 0\n#ENDVAR\nG1 F100\n$WHILE V.L.I < 100\n" \
              "V.L.I = V.L.I + 1\nG1 X[V.L.I]\n$ENDWHILE\nM30"
    assert len(ends(program)) == 100


@pytest.mark.parametrize(
    ("program", "err", "line", "column"),
    [
        ("$ENDIF\nM30", NcErrorId.ENDIF_WITHOUT_IF, 1, 1),
        ("$ELSE\nM30", NcErrorId.ELSE_WITHOUT_IF, 1, 1),
        ("  $ELSEIF 1\nM30", NcErrorId.ELSE_WITHOUT_IF, 1, 3),
        ("$IF 1\nG0 X1\n", NcErrorId.BLOCK_NOT_CLOSED, 1, 1),
        ("$IF 0\nG0 X1\nM30", NcErrorId.BLOCK_NOT_CLOSED, 1, 1),
        ("$IF 0\n$WHILE 1\n$ENDIF\nM30", NcErrorId.ENDIF_WITHOUT_IF, 3, 1),
        ("$WHILE 0\n$IF 1\n$ENDWHILE\nM30", NcErrorId.LOOP_END_WITHOUT_BEGIN, 3, 1),
        ("$WHILE 1\n$IF 1\n$ENDWHILE\nM30", NcErrorId.LOOP_END_WITHOUT_BEGIN, 3, 1),
        ("$ENDWHILE\nM30", NcErrorId.LOOP_END_WITHOUT_BEGIN, 1, 1),
        ("$ENDFOR\nM30", NcErrorId.LOOP_END_WITHOUT_BEGIN, 1, 1),
        ("$UNTIL 1\nM30", NcErrorId.LOOP_END_WITHOUT_BEGIN, 1, 1),
        ("#RT ENDWHILE\nM30", NcErrorId.LOOP_END_WITHOUT_BEGIN, 1, 1),
        ("$CASE 1\nM30", NcErrorId.SWITCH_PART_WITHOUT_SWITCH, 1, 1),
        ("$DEFAULT\nM30", NcErrorId.SWITCH_PART_WITHOUT_SWITCH, 1, 1),
        ("$ENDSWITCH\nM30", NcErrorId.SWITCH_PART_WITHOUT_SWITCH, 1, 1),
        ("$SWITCH 1\n$CASE 1\nM30", NcErrorId.BLOCK_NOT_CLOSED, 1, 1),
        ("$BREAK\nM30", NcErrorId.BREAK_OUTSIDE_LOOP, 1, 1),
        ("$IF 1\n$CONTINUE\n$ENDIF\nM30", NcErrorId.BREAK_OUTSIDE_LOOP, 2, 1),
        ("#VAR\nV.P.K\n#ENDVAR\n$FOR V.P.K = 1, 2, 0\n$ENDFOR\nM30", NcErrorId.FOR_STEP_ZERO, 4, 1),
        ("$FOO\nM30", NcErrorId.UNKNOWN_CONTROL_KEYWORD, 1, 1),
        ("$DO\nM30", NcErrorId.INSTRUCTION_NOT_SUPPORTED, 1, 1),
        ("G0 X1 $IF 1\nM30", NcErrorId.UNKNOWN_CONTROL_KEYWORD, 1, 7),
        ("$ENDIF X1\nM30", NcErrorId.UNKNOWN_WORD, 1, 8),
        ("#VAR\nV.L.A\n#ENDVAR\n$IF V.L.A = 1\n$ENDIF\nM30", NcErrorId.EXPRESSION_SYNTAX, 4, 11),
        ("$IF\nM30", NcErrorId.EXPRESSION_SYNTAX, 1, 4),
        ('$IF "a"\n$ENDIF\nM30', NcErrorId.TYPE_MISMATCH, 1, 1),
        ("$GOTO N99\nM30", NcErrorId.LABEL_NOT_FOUND, 1, 1),
        ("$GOTO [NOPE]\nM30", NcErrorId.LABEL_NOT_FOUND, 1, 1),
        ("$GOTO X10\nM30", NcErrorId.BAD_GOTO_TARGET, 1, 7),
        ("$GOTO N1 $GOTO N1\nN1: M30", NcErrorId.WORD_REPEATED, 1, 10),
        ("L sub1 L sub2\nM30", NcErrorId.WORD_REPEATED, 1, 8),  # two calls in one block
        ("#MSG SAVE [\"x %f\"]\nM30", NcErrorId.MESSAGE_FORMAT, 1, 12),
        ("#WAIT\nM30", NcErrorId.INSTRUCTION_NOT_SUPPORTED, 1, 1),
        ("N5 #CONTOUR LOOKAHEAD LOG ON\nM30", NcErrorId.CONTOUR_LOOKAHEAD_NOT_ENABLED, 1, 4),
        ("N5 #CONTOUR MODE [DEV]\nM30", NcErrorId.INSTRUCTION_NOT_SUPPORTED, 1, 4),
        ("#RT CLEAR\nM30", NcErrorId.INSTRUCTION_NOT_SUPPORTED, 1, 1),
    ],
)
def test_control_errors(program, err, line, column) -> None:
    e = error_of(program)
    assert (e.id, e.line, e.column) == (err, line, column), str(e)


def test_control_error_messages() -> None:
    assert error_of("$ENDIF\nM30").message == "$ENDIF without $IF"
    assert error_of("$IF 0\nM30").message == "$IF without $ENDIF"
    assert error_of("$GOTO [FOO]\nM30").message == "label [FOO] not found"
    assert error_of("#MSG SAVE\nM30").message == "'[\"<text>\", ...]' expected after #MSG"
    assert error_of("#WAIT\nM30").message == "#WAIT is not supported yet"


def test_error_comes_after_the_blocks_before_it() -> None:
    d = decoder("G0 X1\nG0 X2\nQ5\nM30")
    blocks = d.blocks()
    assert next(blocks).motion.end_mm[0] == 1
    assert next(blocks).motion.end_mm[0] == 2
    with pytest.raises(Exception) as info:
        next(blocks)
    assert info.value.line == 3
