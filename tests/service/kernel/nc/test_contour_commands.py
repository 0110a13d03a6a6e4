"""Contour look-ahead commands (ISG FCT-C40): #CONTOUR LOOKAHEAD LOG, #DISTANCE PROG START
CLEAR, the log area in the modal state and the markers of real-time loops."""

from __future__ import annotations

from dataclasses import replace
from itertools import islice

import pytest

from cnc_objects.service.kernel.nc import (
    Block,
    ContourCommand,
    ContourKind,
    LogArea,
    ModalState,
    NcError,
    NcErrorId,
    check_syntax,
    work_guard,
)

from .support import AXES, decode, decoder, error_of, slow

ON, PARAM, OFF = ContourKind.LOG_ON, ContourKind.LOG_PARAM, ContourKind.LOG_OFF
CLEAR, DISTANCE = ContourKind.LOG_CLEAR, ContourKind.DISTANCE_CLEAR
PASS, END = ContourKind.RT_PASS, ContourKind.RT_END
VARS = "#VAR\nV.L.A = 3\nV.P.X = 1.5\n#ENDVAR\n"
NOT_ENABLED = ("#CONTOUR LOOKAHEAD needs the contour look-ahead function: add FCT_CONTOUR_LAH "
               "to the channel's interpolator_function (P-CHAN-00650)")
CLEAR_IN_LOOP = "#CONTOUR LOOKAHEAD LOG CLEAR is not allowed inside #RT WHILE"


def run(text: str, **kw) -> list[Block]:
    """All blocks of ``text`` decoded with the contour look-ahead function."""
    return decode(text, contour_lookahead=True, **kw)


def commands(text: str, **kw) -> list[ContourCommand]:
    """The contour command of every block that has one."""
    return [b.contour for b in run(text, **kw) if b.contour is not None]


def trace(blocks: list[Block]) -> list[tuple]:
    """A readable account of blocks: ("PASS", loop, pass), ("END", loop), the LOG
    commands by kind name, motions as ("X", end x)."""
    out: list[tuple] = []
    for b in blocks:
        c = b.contour
        if c is None:
            if b.motion is not None:
                out.append(("X", b.motion.end_mm[0]))
        elif c.kind == PASS:
            out.append(("PASS", c.loop, c.rt_pass))
        elif c.kind == END:
            out.append(("END", c.loop))
        else:
            out.append((c.kind.name, c.param))
    return out


def loop(count: int, body: str = "G1 X[V.L.I]", name: str = "I") -> str:
    """An #RT WHILE loop of ``count`` passes over ``body`` (V.L.<name> counts from 1)."""
    return (f"V.L.{name} = 0\n#RT WHILE [V.L.{name} < {count}]\nV.L.{name} = V.L.{name} + 1\n"
            f"{body}\n#RT ENDWHILE\n")


def program(*parts: str) -> str:
    """A main program declaring V.L.I and V.L.J, with a feed, ending with M30."""
    return "#VAR\nV.L.I = 0\nV.L.J = 0\n#ENDVAR\nG1 F600\n" + "".join(parts) + "M30"


# ---------------------------------------------------------------- syntax forms


@pytest.mark.parametrize(
    ("line", "kind", "param"),
    [
        ("#CONTOUR LOOKAHEAD LOG ON", ON, None),
        ("#CONTOUR LOOKAHEAD LOG ON [PARAM=1]", ON, 1.0),
        ("#contour lookahead log on param=2.5", ON, 2.5),
        ("# Contour  LookAhead\tLog On [ PARAM = 7 ]", ON, 7.0),
        ("#CONTOUR LOOKAHEAD LOG OFF", OFF, None),
        ("#CONTOUR LOOKAHEAD LOG OFF [PARAM=-.5]", OFF, -0.5),
        ("#CONTOUR LOOKAHEAD LOG OFF PARAM=-V.L.A", OFF, -3.0),
        ("#CONTOUR LOOKAHEAD LOG [PARAM=[V.L.A*2]]", PARAM, 6.0),
        ("#CONTOUR LOOKAHEAD LOG [PARAM=V.P.X]", PARAM, 1.5),
        ("#CONTOUR LOOKAHEAD LOG PARAM = SQRT[16] + V.L.A", PARAM, 7.0),
        ("#CONTOUR LOOKAHEAD LOG [PARAM=TRUE]", PARAM, 1.0),
        ("#CONTOUR LOOKAHEAD LOG CLEAR", CLEAR, None),
        ("#DISTANCE PROG START CLEAR", DISTANCE, None),
        ("#distance program start clear", DISTANCE, None),
    ],
)
def test_syntax_forms(line, kind, param) -> None:
    assert commands(VARS + line + "\nM30") == [ContourCommand(kind, param)]


def test_the_command_block_has_the_number_and_the_place_of_the_hash() -> None:
    blocks = run("G1 X1 F100\nN20 [MARK] #CONTOUR LOOKAHEAD LOG ON [PARAM=1]\n"
                 "  #DISTANCE PROG START CLEAR\nM30")
    on, distance = blocks[1], blocks[2]
    assert (on.number, on.source.file, on.source.line, on.source.column) == (20, "prog.nc", 2, 12)
    assert (distance.number, distance.source.line, distance.source.column) == (None, 3, 3)
    for block in (on, distance):
        assert block.motion is None and block.axis_exchange is None and not block.manual
        assert not block.needs_stop  # the path runs through; only CLEAR stops it


def test_the_hash_on_a_continuation_line() -> None:
    blocks = run("N7 \\\n#CONTOUR LOOKAHEAD LOG ON\nM30")
    assert (blocks[0].number, blocks[0].source.line, blocks[0].source.column) == (7, 2, 1)


def test_clear_stops_the_path() -> None:
    blocks = run("#CONTOUR LOOKAHEAD LOG CLEAR\nM30")
    assert blocks[0].contour == ContourCommand(CLEAR) and blocks[0].needs_stop


def test_manual_blocks_are_marked_manual() -> None:
    block = run("#CONTOUR LOOKAHEAD LOG ON", manual=True)[0]
    assert block.manual and block.contour == ContourCommand(ON)


def test_a_block_is_produced_even_when_the_area_does_not_change() -> None:
    text = "\n".join(["#CONTOUR LOOKAHEAD LOG OFF", "#CONTOUR LOOKAHEAD LOG ON",
                      "#CONTOUR LOOKAHEAD LOG ON", "#CONTOUR LOOKAHEAD LOG [PARAM=2]",
                      "#CONTOUR LOOKAHEAD LOG OFF", "#CONTOUR LOOKAHEAD LOG OFF", "M30"])
    assert [c.kind for c in commands(text)] == [OFF, ON, ON, PARAM, OFF, OFF]


def test_distance_clear_works_without_the_contour_lookahead_function() -> None:
    blocks = decode("#DISTANCE PROG START CLEAR\nM30")
    assert blocks[0].contour == ContourCommand(DISTANCE)


# ---------------------------------------------------------------- errors


@pytest.mark.parametrize(
    "line",
    ["#CONTOUR LOOKAHEAD LOG ON", "#CONTOUR LOOKAHEAD LOG OFF [PARAM=1]",
     "#CONTOUR LOOKAHEAD LOG [PARAM=1]", "#CONTOUR LOOKAHEAD LOG CLEAR"],
)
def test_contour_lookahead_needs_the_function(line) -> None:
    e = error_of(f"G1 X1 F100\nN10 {line}\nM30")
    assert (e.id, e.file, e.line, e.column, e.message) == (
        NcErrorId.CONTOUR_LOOKAHEAD_NOT_ENABLED, "prog.nc", 2, 5, NOT_ENABLED)


@pytest.mark.parametrize(
    ("line", "column", "text"),
    [
        ("#CONTOUR", 9, "LOOKAHEAD expected after #CONTOUR, found the end of the line"),
        ("#CONTOUR LOOKAHEAD", 19, "LOG expected after #CONTOUR LOOKAHEAD"),
        ("#CONTOUR LOOKAHEAD ON", 20, "LOG expected after #CONTOUR LOOKAHEAD, found 'ON'"),
        ("#CONTOUR LOOKAHEAD LOG", 23, "ON, OFF, CLEAR or [PARAM=..] expected"),
        ("#CONTOUR LOOKAHEAD LOG FOO", 24, "ON, OFF, CLEAR or [PARAM=..] expected after "
                                           "#CONTOUR LOOKAHEAD LOG, found 'FOO'"),
        ("#CONTOUR LOOKAHEAD LOG ONX", 24, "found 'ONX'"),
        ("#CONTOUR LOOKAHEAD LOG CLEAR [PARAM=1]", 30, "LOG CLEAR takes no PARAM"),
        ("#CONTOUR LOOKAHEAD LOG CLEAR PARAM=1", 30, "LOG CLEAR takes no PARAM"),
        ("#CONTOUR LOOKAHEAD LOG ON [PARAM=1", 35,
         "']' expected to close the '[' at column 27, found the end of the line"),
        ("#CONTOUR LOOKAHEAD LOG ON [PARAM=1 2]", 36, "']' expected"),
        ("#CONTOUR LOOKAHEAD LOG ON [PARAM 1]", 34, "'=' expected after PARAM, found '1]'"),
        ("#CONTOUR LOOKAHEAD LOG ON PARAM", 32, "'=' expected after PARAM"),
        ("#CONTOUR LOOKAHEAD LOG ON [X=1]", 28, "PARAM expected after '['"),
        ("#CONTOUR LOOKAHEAD LOG [PARAM]", 30, "'=' expected after PARAM"),
        ("#CONTOUR LOOKAHEAD LOG ON X1", 27,
         "#CONTOUR LOOKAHEAD LOG ON must stand alone in its NC line, found 'X1'"),
        ("#CONTOUR LOOKAHEAD LOG OFF [PARAM=1] M3", 38, "found 'M3'"),
        ("#CONTOUR LOOKAHEAD LOG [PARAM=1] [PARAM=2]", 34, "must stand alone"),
        ("#CONTOUR LOOKAHEAD LOG CLEAR G4 X1", 30, "must stand alone"),
        ("#DISTANCE", 10, "PROG or PROGRAM expected after #DISTANCE, found the end of the line"),
        ("#DISTANCE START CLEAR", 11, "PROG or PROGRAM expected after #DISTANCE, found 'START'"),
        ("#DISTANCE PROG CLEAR", 16, "START expected after #DISTANCE PROG, found 'CLEAR'"),
        ("#DISTANCE PROGRAM START", 24, "CLEAR expected after #DISTANCE PROGRAM START"),
        ("#DISTANCE PROG START CLEAR X1", 28,
         "#DISTANCE PROG START CLEAR must stand alone in its NC line, found 'X1'"),
        ("G1 X1 #CONTOUR LOOKAHEAD LOG ON", 7, "#CONTOUR must stand alone in its NC line"),
        ("M3 # distance PROG START CLEAR", 4, "#DISTANCE must stand alone in its NC line"),
    ],
)
def test_syntax_errors(line, column, text) -> None:
    for enabled in (True, False):  # a syntax error is found before the function is missed
        e = error_of("G1 X0 F100\n" + line + "\nM30", contour_lookahead=enabled)
        assert (e.id, e.line, e.column) == (NcErrorId.CONTOUR_COMMAND_SYNTAX, 2, column), str(e)
        assert text in e.message


@pytest.mark.parametrize(
    ("line", "err", "column"),
    [
        ('#CONTOUR LOOKAHEAD LOG ON [PARAM="a"]', NcErrorId.TYPE_MISMATCH, 34),
        ("#CONTOUR LOOKAHEAD LOG [PARAM=" + "9" * 400 + "]", NcErrorId.VALUE_OUT_OF_RANGE, 31),
        ("#CONTOUR LOOKAHEAD LOG OFF PARAM=1/0", NcErrorId.DIVISION_BY_ZERO, 35),
        ("#CONTOUR LOOKAHEAD LOG ON [PARAM=1+]", NcErrorId.EXPRESSION_SYNTAX, 36),
        ("#CONTOUR LOOKAHEAD LOG ON [PARAM=V.L.NOPE]", NcErrorId.UNDECLARED_VARIABLE, 34),
        ("#CONTOUR MODE [DEV PATH_DEV=0.1]", NcErrorId.INSTRUCTION_NOT_SUPPORTED, 1),
    ],
)
def test_param_errors(line, err, column) -> None:
    modal = ModalState()
    e = error_of(line + "\nM30", contour_lookahead=True, modal=modal)
    assert (e.id, e.line, e.column) == (err, 1, column), str(e)
    assert modal.contour_log_area == LogArea.NONE  # an error changes nothing


@pytest.mark.parametrize(
    ("text", "files", "where"),
    [
        (program("#RT WHILE\n#CONTOUR LOOKAHEAD LOG CLEAR\n#RT ENDWHILE\n"), {},
         ("prog.nc", 7, 1)),
        (program("#CONTOUR LOOKAHEAD LOG ON\n",
                 loop(3, "$IF V.L.I == 2\n  N9 #CONTOUR LOOKAHEAD LOG CLEAR\n$ENDIF")),
         {}, ("prog.nc", 11, 6)),
        (program(loop(2, "$WHILE V.L.J < 1\nV.L.J = 1\n#CONTOUR LOOKAHEAD LOG CLEAR\n"
                         "$ENDWHILE")), {}, ("prog.nc", 11, 1)),
        (program(loop(2, "L clear.nc")), {"clear.nc": "G1 X5\n#CONTOUR LOOKAHEAD LOG CLEAR\nM17"},
         ("clear.nc", 2, 1)),
        (program(loop(2, "L outer.nc")),
         {"outer.nc": "LL CLR\nM17\n%L CLR\n#CONTOUR LOOKAHEAD LOG CLEAR\nM17"},
         ("outer.nc", 4, 1)),
    ],
)
def test_clear_inside_a_real_time_loop_is_an_error(text, files, where) -> None:
    e = error_of(text, files=files, contour_lookahead=True)
    assert (e.id, e.file, e.line, e.column, e.message) == (
        NcErrorId.CONTOUR_CLEAR_IN_RT_LOOP, *where, CLEAR_IN_LOOP)


def test_clear_outside_a_real_time_loop_is_fine() -> None:
    text = program(
        "#CONTOUR LOOKAHEAD LOG ON\n", loop(2),
        "#CONTOUR LOOKAHEAD LOG CLEAR\n",  # after the loop
        "#RT WHILE [V.L.I < 0]\n#CONTOUR LOOKAHEAD LOG CLEAR\n#RT ENDWHILE\n",  # never runs
        "$WHILE V.L.J < 2\nV.L.J = V.L.J + 1\n#CONTOUR LOOKAHEAD LOG CLEAR\n$ENDWHILE\n",
        "L sub.nc\n",
    )
    files = {"sub.nc": "#CONTOUR LOOKAHEAD LOG CLEAR\nM17"}
    assert [c.kind for c in commands(text, files=files) if c.kind == CLEAR] == [CLEAR] * 4


# ---------------------------------------------------------------- the log area


def test_log_area_after_sequences() -> None:
    modal = ModalState()
    steps = [
        ("#CONTOUR LOOKAHEAD LOG ON", LogArea.OPEN),
        ("#CONTOUR LOOKAHEAD LOG ON [PARAM=2]", LogArea.OPEN),
        ("#CONTOUR LOOKAHEAD LOG [PARAM=3]", LogArea.OPEN),
        ("#CONTOUR LOOKAHEAD LOG OFF", LogArea.CLOSED),
        ("#CONTOUR LOOKAHEAD LOG ON", LogArea.CLOSED),  # only the first area counts
        ("#CONTOUR LOOKAHEAD LOG OFF", LogArea.CLOSED),
        ("#DISTANCE PROG START CLEAR", LogArea.CLOSED),
        ("#CONTOUR LOOKAHEAD LOG CLEAR", LogArea.NONE),
        ("#CONTOUR LOOKAHEAD LOG OFF", LogArea.NONE),
        ("#CONTOUR LOOKAHEAD LOG ON", LogArea.OPEN),
        ("#CONTOUR LOOKAHEAD LOG CLEAR", LogArea.NONE),
    ]
    for line, area in steps:  # manual blocks, one after the other, on one modal state
        blocks = run(line, modal=modal, manual=True)
        assert len(blocks) == 1 and blocks[0].manual
        assert modal.contour_log_area == area, line


def test_a_program_start_clears_the_area_and_a_manual_decoder_keeps_it() -> None:
    modal = ModalState()
    d = decoder("#CONTOUR LOOKAHEAD LOG ON\nM30", modal=modal, contour_lookahead=True)
    list(d.blocks())
    assert d.modal.contour_log_area == LogArea.OPEN
    # manual blocks continue in the open area: a real-time loop gets markers
    blocks = run("#VAR\nV.L.I = 0\n#ENDVAR\n" + loop(1, "G1 X4 F100"), modal=modal, manual=True)
    assert trace(blocks) == [("PASS", 1, 1), ("X", 4.0), ("END", 1)]
    assert modal.contour_log_area == LogArea.OPEN
    assert all(b.manual for b in blocks)
    decoder("M30", modal=modal, contour_lookahead=True)  # a program start
    assert modal.contour_log_area == LogArea.NONE
    modal.contour_log_area = LogArea.CLOSED
    decoder("G1 X1", modal=modal, manual=True)
    assert modal.contour_log_area == LogArea.CLOSED


# ---------------------------------------------------------------- real-time loop markers


def test_a_loop_entered_in_an_open_area_gets_a_marker_per_pass() -> None:
    text = program("N10 #CONTOUR LOOKAHEAD LOG ON [PARAM=1]\n", loop(3),
                   "#CONTOUR LOOKAHEAD LOG ON [PARAM=8]\n")
    blocks = run(text)
    assert trace(blocks) == [
        ("LOG_ON", 1.0), ("PASS", 1, 1), ("X", 1.0), ("PASS", 1, 2), ("X", 2.0),
        ("PASS", 1, 3), ("X", 3.0), ("END", 1), ("LOG_ON", 8.0),
    ]
    markers = [b for b in blocks if b.contour is not None and b.contour.kind in (PASS, END)]
    assert {(b.source.line, b.source.column, b.number, b.motion) for b in markers} == {
        (8, 1, None, None)}
    assert all(not b.needs_stop for b in markers)


def test_a_marker_has_the_number_and_the_hash_of_its_rt_while() -> None:
    text = program("#CONTOUR LOOKAHEAD LOG ON\nV.L.I = 0\n",
                   "  N60 #RT WHILE [V.L.I < 1]\nV.L.I = 1\nG1 X2\n#RT ENDWHILE\n")
    markers = [b for b in run(text) if b.contour is not None and b.contour.kind in (PASS, END)]
    assert [(b.contour, b.number, b.source.line, b.source.column) for b in markers] == [
        (ContourCommand(PASS, loop=1, rt_pass=1), 60, 8, 7),
        (ContourCommand(END, loop=1), 60, 8, 7)]


def test_log_on_inside_the_loop_gives_no_markers() -> None:
    # ISG's example: the area is opened inside the loop, its elements are logged once
    body = "#CONTOUR LOOKAHEAD LOG ON [PARAM=1]\nG1 X[V.L.I]\n#CONTOUR LOOKAHEAD LOG ON [PARAM=8]"
    assert trace(run(program(loop(2, body)))) == [
        ("LOG_ON", 1.0), ("X", 1.0), ("LOG_ON", 8.0),
        ("LOG_ON", 1.0), ("X", 2.0), ("LOG_ON", 8.0)]


@pytest.mark.parametrize(
    "before",
    ["", "#CONTOUR LOOKAHEAD LOG ON\n#CONTOUR LOOKAHEAD LOG OFF\n",
     "#CONTOUR LOOKAHEAD LOG ON\n#CONTOUR LOOKAHEAD LOG CLEAR\n"],
)
def test_a_loop_outside_an_open_area_gets_no_markers(before) -> None:
    blocks = run(program(before, loop(3)))
    assert [e for e in trace(blocks) if e[0] == "X"] == [("X", 1.0), ("X", 2.0), ("X", 3.0)]
    assert all(b.contour.kind not in (PASS, END) for b in blocks if b.contour is not None)


def test_a_loop_false_at_entry_gets_no_markers() -> None:
    text = program("#CONTOUR LOOKAHEAD LOG ON\nG1 X7\n", loop(0), "G1 X8\n")
    assert trace(run(text)) == [("LOG_ON", None), ("X", 7.0), ("X", 8.0)]


def test_log_off_inside_the_tracked_loop_keeps_its_markers() -> None:
    body = "G1 X[V.L.I]\n#CONTOUR LOOKAHEAD LOG OFF"
    assert trace(run(program("#CONTOUR LOOKAHEAD LOG ON\n", loop(2, body)))) == [
        ("LOG_ON", None), ("PASS", 1, 1), ("X", 1.0), ("LOG_OFF", None),
        ("PASS", 1, 2), ("X", 2.0), ("LOG_OFF", None), ("END", 1)]


def test_break_out_of_the_tracked_loop_ends_it() -> None:
    body = "G1 X[V.L.I]\n$IF V.L.I == 2\n$BREAK\n$ENDIF\nG1 Y[V.L.I]"
    text = program("#CONTOUR LOOKAHEAD LOG ON\n", loop(5, body), "G1 X9\n")
    assert trace(run(text)) == [
        ("LOG_ON", None), ("PASS", 1, 1), ("X", 1.0), ("X", 1.0), ("PASS", 1, 2), ("X", 2.0),
        ("END", 1), ("X", 9.0)]


def test_break_out_of_an_inner_loop_does_not_end_the_tracked_one() -> None:
    inner = "$WHILE TRUE\nG1 Y[V.L.I]\n$BREAK\n$ENDWHILE\nG1 X[V.L.I]"
    text = program("#CONTOUR LOOKAHEAD LOG ON\n", loop(2, inner))
    assert trace(run(text)) == [
        ("LOG_ON", None), ("PASS", 1, 1), ("X", 0.0), ("X", 1.0), ("PASS", 1, 2),
        ("X", 1.0), ("X", 2.0), ("END", 1)]


def test_continue_starts_the_next_pass() -> None:
    body = "$IF V.L.I == 1\n$CONTINUE\n$ENDIF\nG1 X[V.L.I]"
    text = program("#CONTOUR LOOKAHEAD LOG ON\n", loop(3, body))
    assert trace(run(text)) == [
        ("LOG_ON", None), ("PASS", 1, 1), ("PASS", 1, 2), ("X", 2.0), ("PASS", 1, 3),
        ("X", 3.0), ("END", 1)]


def test_nested_loops_give_markers_of_the_outer_loop_only() -> None:
    inner = loop(2, "G1 X[V.L.I * 10 + V.L.J]", name="J")
    text = program("#CONTOUR LOOKAHEAD LOG ON\n", loop(2, inner.rstrip("\n")), "G1 X0\n")
    assert trace(run(text)) == [
        ("LOG_ON", None), ("PASS", 1, 1), ("X", 11.0), ("X", 12.0),
        ("PASS", 1, 2), ("X", 21.0), ("X", 22.0), ("END", 1), ("X", 0.0)]


def test_an_inner_loop_entered_after_log_on_inside_an_outer_loop_is_tracked() -> None:
    inner = loop(1, "G1 X[V.L.I]", name="J")
    body = "#CONTOUR LOOKAHEAD LOG ON\n" + inner.rstrip("\n")
    assert trace(run(program(loop(2, body)))) == [
        ("LOG_ON", None), ("PASS", 1, 1), ("X", 1.0), ("END", 1),
        ("LOG_ON", None), ("PASS", 2, 1), ("X", 2.0), ("END", 2)]


def test_loops_are_numbered_per_decoder() -> None:
    files = {"sub.nc": "#VAR\nV.L.K = 0\n#ENDVAR\n" + loop(1, "G1 X5\nX6", name="K") + "M17"}
    text = program("#CONTOUR LOOKAHEAD LOG ON\n", loop(1), "L sub.nc\nL sub.nc\n")
    assert trace(run(text, files=files)) == [
        ("LOG_ON", None), ("PASS", 1, 1), ("X", 1.0), ("END", 1),
        ("PASS", 2, 1), ("X", 5.0), ("X", 6.0), ("END", 2),
        ("PASS", 3, 1), ("X", 5.0), ("X", 6.0), ("END", 3)]
    assert trace(run(text, files=files)) == trace(run(text, files=files))  # starts at 1


def test_a_subprogram_inside_the_tracked_loop_adds_no_markers() -> None:
    files = {"sub.nc": "#VAR\nV.L.K = 0\n#ENDVAR\n" + loop(2, "G1 Y[V.L.K]", name="K") + "M17"}
    text = program("#CONTOUR LOOKAHEAD LOG ON\n", loop(2, "L sub.nc"))
    assert [e for e in trace(run(text, files=files)) if e[0] != "X"] == [
        ("LOG_ON", None), ("PASS", 1, 1), ("PASS", 1, 2), ("END", 1)]


def test_goto_out_of_the_tracked_loop_ends_the_tracking_without_a_marker() -> None:
    body = "G1 X[V.L.I]\n$IF V.L.I == 2\n$GOTO [OUT]\n$ENDIF"
    text = program("#CONTOUR LOOKAHEAD LOG ON\n", loop(5, body), "[OUT] G1 X9\n",
                   loop(1, "G1 X[20]", name="J"))
    assert trace(run(text)) == [
        ("LOG_ON", None), ("PASS", 1, 1), ("X", 1.0), ("PASS", 1, 2), ("X", 2.0), ("X", 9.0),
        ("PASS", 2, 1), ("X", 20.0), ("END", 2)]


def test_an_endless_real_time_loop_gives_markers_as_long_as_pulled() -> None:
    d = decoder("#CONTOUR LOOKAHEAD LOG ON\nG1 F100\n#RT WHILE\nG1 X1\nG1 X2\n#RT ENDWHILE\nM30",
                contour_lookahead=True)
    assert trace(list(islice(d.blocks(), 8))) == [
        ("LOG_ON", None), ("PASS", 1, 1), ("X", 1.0), ("X", 2.0), ("PASS", 1, 2), ("X", 1.0),
        ("X", 2.0), ("PASS", 1, 3)]


def test_markers_do_not_count_for_the_endless_loop_guard(monkeypatch) -> None:
    monkeypatch.setattr(work_guard, "IDLE_STEPS_MAX", 50)
    d = decoder("#CONTOUR LOOKAHEAD LOG ON\nG0 X1\n#RT WHILE\n#RT ENDWHILE\nM30",
                contour_lookahead=True)
    got = []
    with pytest.raises(NcError) as info:  # (bounded: if markers counted, it would never end)
        for block in islice(d.blocks(), 1000):
            got.append(block)
    assert (info.value.id, info.value.line) == (NcErrorId.ENDLESS_LOOP, 4)
    assert trace(got)[:3] == [("LOG_ON", None), ("X", 1.0), ("PASS", 1, 1)]
    # the markers of the passes (2 steps each) up to the first look past the limit
    assert len(got) == 2 + work_guard.LOOK_EVERY_STEPS // 2


# ---------------------------------------------------------------- paths, syntax check


def test_hot_and_general_path_agree() -> None:
    lines = ["G1 X0 Y0 Z0 F1200", "#VAR", "V.L.I = 0", "#ENDVAR"]
    lines += [f"N{k} X{k} Y{k % 7} Z{k % 3}" for k in range(1, 20)]
    lines += ["N100 #CONTOUR LOOKAHEAD LOG ON [PARAM=1]", "X20 Y1", "G2 X22 I1",
              "#RT WHILE [V.L.I < 3]", "V.L.I = V.L.I + 1", "G1 X[30 + V.L.I]", "Y5",
              "#RT ENDWHILE", "#CONTOUR LOOKAHEAD LOG [PARAM=2]"]
    lines += [f"G1 X{k} Z{k % 4}" for k in range(40, 50)]
    lines += ["#CONTOUR LOOKAHEAD LOG OFF", "#DISTANCE PROG START CLEAR", "X0 Y0",
              "#CONTOUR LOOKAHEAD LOG CLEAR", "M30"]
    text = "\n".join(lines)
    fast = run(text)
    # slow() makes the lines longer: all but the byte offsets must be the same
    assert [replace(b, source=replace(b.source, offset=0)) for b in fast] == [
        replace(b, source=replace(b.source, offset=0)) for b in run(slow(text))]
    kinds = [b.contour.kind for b in fast if b.contour is not None]
    assert kinds == [ON, PASS, PASS, PASS, END, PARAM, OFF, DISTANCE, CLEAR]
    assert len(fast) == 1 + 19 + 1 + 2 + 4 + 6 + 1 + 10 + 2 + 1 + 1 + 1


def test_check_syntax_reports_malformed_commands_only() -> None:
    text = "\n".join([
        "#CONTOUR LOOKAHEAD LOG ON [PARAM=1]",
        "#CONTOUR LOOKAHEAD LOG",
        "#CONTOUR LOOKAHEAD LOG [PARAM=V.L.X * 2]",
        "#RT WHILE",
        "#CONTOUR LOOKAHEAD LOG CLEAR",  # 22073 needs the program to run
        "#RT ENDWHILE",
        "#CONTOUR LOOKAHEAD LOG CLEAR [PARAM=2]",
        "#DISTANCE PROGRAM START CLEAR",
        "#DISTANCE PROG START",
        "G1 X1 #CONTOUR LOOKAHEAD LOG OFF",
        "#CONTOUR LOOKAHEAD LOG OFF PARAM=1 X2",
        "M30",
    ])
    errors = check_syntax(text, "p.nc", axes=AXES)
    assert [(e.id, e.line, e.column) for e in errors] == [
        (NcErrorId.CONTOUR_COMMAND_SYNTAX, 2, 23), (NcErrorId.CONTOUR_COMMAND_SYNTAX, 7, 30),
        (NcErrorId.CONTOUR_COMMAND_SYNTAX, 9, 21), (NcErrorId.CONTOUR_COMMAND_SYNTAX, 10, 7),
        (NcErrorId.CONTOUR_COMMAND_SYNTAX, 11, 36)]
    good = "#CONTOUR LOOKAHEAD LOG ON\n#contour lookahead log [param=-.5]\n" \
           "#CONTOUR LOOKAHEAD LOG OFF PARAM=[V.L.A*2]\n#CONTOUR LOOKAHEAD LOG CLEAR\n" \
           "#DISTANCE PROG START CLEAR\nM30"
    assert check_syntax(good, "p.nc", axes=AXES) == []
