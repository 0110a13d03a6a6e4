"""Axis exchange: #AX RELEASE / #AX REQUEST, released axes in the modal state."""

from __future__ import annotations

from dataclasses import replace

import pytest

from cnc_objects.service.kernel.nc import (
    AxisExchange,
    AxisExchangeKind,
    Block,
    ModalState,
    NcError,
    NcErrorId,
    SourceRef,
    StopKind,
    check_syntax,
)

from .support import AXES, decode, decoder, error_of, slow

RELEASE = AxisExchangeKind.RELEASE
REQUEST = AxisExchangeKind.REQUEST
RELEASED_Y = "axis Y is not in the channel (released by #AX RELEASE)"


def exchanges(text: str, **kw) -> list[AxisExchange]:
    """The axis_exchange of every block that has one."""
    return [b.axis_exchange for b in decode(text, **kw) if b.axis_exchange is not None]


# ---------------------------------------------------------------- release


def test_release_by_name_gives_a_stopping_block_without_motion() -> None:
    program = "G1 X1 Y2 Z3 F600\nN20 #AX RELEASE [Y]\nX5 Z4\nM30"
    for text in (program, slow(program)):
        d = decoder(text)
        blocks = list(d.blocks())
        assert len(blocks) == 4
        exchange = blocks[1]
        assert exchange.axis_exchange == AxisExchange(RELEASE, (1,))
        assert exchange.number == 20
        assert (exchange.source.line, exchange.source.column) == (2, 1)
        assert exchange.motion is None and exchange.stop == StopKind.NONE
        assert exchange.needs_stop and not blocks[0].needs_stop
        # the released axis keeps its position
        assert blocks[2].motion.start_mm == (1.0, 2.0, 3.0)
        assert blocks[2].motion.end_mm == (5.0, 2.0, 4.0)
        assert blocks[2].axis_exchange is None
        assert d.modal.released_axes == frozenset({1})


def test_needs_stop_for_an_axis_exchange() -> None:
    src = SourceRef("f.nc", 1)
    assert Block(src, axis_exchange=AxisExchange(REQUEST, (0,))).needs_stop
    assert not Block(src).needs_stop


def test_keywords_and_names_are_case_insensitive_and_keep_the_programmed_order() -> None:
    assert exchanges("#ax Release [ z , x ]\nM30") == [AxisExchange(RELEASE, (2, 0))]


def test_release_by_number_with_expressions() -> None:
    program = "#VAR\nV.L.N = 1\n#ENDVAR\n#AX RELEASE NBR [V.L.N + 2, V.L.N]\nM30"
    assert exchanges(program) == [AxisExchange(RELEASE, (2, 0))]


def test_release_by_configured_axis_numbers() -> None:
    d = decoder("#AX RELEASE NBR [2 * 3]\nM30", axis_numbers=(5, 6, 7))
    blocks = list(d.blocks())
    assert blocks[0].axis_exchange == AxisExchange(RELEASE, (1,))
    assert d.modal.released_axes == frozenset({1})


def test_release_all_moves_the_axes_still_in_the_channel() -> None:
    program = "#AX RELEASE [Y]\n#AX RELEASE ALL\nM30"
    assert exchanges(program) == [AxisExchange(RELEASE, (1,)), AxisExchange(RELEASE, (0, 2))]


def test_duplicates_are_dropped() -> None:
    assert exchanges("#AX RELEASE [X, Y, X]\nM30") == [AxisExchange(RELEASE, (0, 1))]
    assert exchanges("#AX RELEASE NBR [3, 3]\nM30") == [AxisExchange(RELEASE, (2,))]


def test_release_of_an_axis_not_in_the_channel_gives_nothing() -> None:
    d = decoder("#AX RELEASE [Y]\nN10 #AX RELEASE [Y]\n#AX RELEASE [W, Y]\n"
                "#AX RELEASE NBR [9]\nG1 X1 F100\nM30")
    blocks = list(d.blocks())
    assert [b.axis_exchange for b in blocks] == [AxisExchange(RELEASE, (1,)), None, None]
    assert [b.source.line for b in blocks] == [1, 5, 6]
    assert d.modal.released_axes == frozenset({1})


# ---------------------------------------------------------------- released axes


@pytest.mark.parametrize(
    ("program", "line", "column", "axis"),
    [
        ("G1 F100\n#AX RELEASE [Y]\nX1 Y2", 3, 4, "Y"),  # a plain (hot path) line
        ("G1 F100\n#AX RELEASE [Y]\nG1 X1 Y2 F100 ()", 3, 7, "Y"),  # the general path
        ("#AX RELEASE NBR [2]\nG91 G0 Y[1]", 2, 8, "Y"),
        ("#AX RELEASE [Z, X]\nG0 Y1 Z1 X1", 2, 7, "Z"),  # the leftmost one
        ("#AX RELEASE [X]\nG2 Y2 I1 F100", 2, 7, "X"),  # I: centre offset of X
        ("#AX RELEASE [Z]\nG18 G3 X2 K1 F100", 2, 11, "Z"),
        ("#AX RELEASE [Y]\nG2 X2 I1 F100", 2, 1, "Y"),  # G17 needs Y
        ("#AX RELEASE [X]\nG19 G0 Y1\nG18 G2 Z2 K1 F100", 3, 5, "X"),  # G18 needs X
    ],
)
def test_programming_a_released_axis_is_an_error(program, line, column, axis) -> None:
    e = error_of(program + "\nM30")
    assert (e.id, e.line, e.column) == (NcErrorId.AXIS_RELEASED, line, column)
    assert e.message.startswith(f"axis {axis} is not in the channel (released by #AX RELEASE)")


def test_the_other_axes_work_while_one_is_released() -> None:
    program = "G1 X1 Y2 F600\n#AX RELEASE [Y]\nG18 G2 X3 I1\nG0 Z5\nM30"
    for text in (program, slow(program)):
        blocks = decode(text)
        arc = blocks[2].motion
        assert (arc.start_mm, arc.end_mm, arc.center_mm) == ((1.0, 2.0, 0.0), (3.0, 2.0, 0.0),
                                                             (0.0, 2.0))
        assert blocks[3].motion.end_mm == (3.0, 2.0, 5.0)


def test_the_time_of_g4_is_no_axis_word() -> None:
    blocks = decode("#AX RELEASE [X]\nG4 X2\nM30")
    assert blocks[1].dwell_s == 2.0 and blocks[1].motion is None


def test_a_release_in_a_subprogram_stays_after_it() -> None:
    files = {"rel.nc": "#AX RELEASE [Y]\nM17\n"}
    e = error_of("L rel.nc\nG1 Y1 F100\nM30", files=files)
    assert (e.id, e.file, e.line, e.column, e.message) == (
        NcErrorId.AXIS_RELEASED, "prog.nc", 2, 4, RELEASED_Y)


# ---------------------------------------------------------------- request


def test_request_brings_the_axis_back() -> None:
    program = "G1 X1 Y2 F600\n#AX RELEASE [Y]\nX3\nN40 #AX REQUEST [Y, 2, 1]\nY5\nM30"
    for text in (program, slow(program)):
        d = decoder(text)
        blocks = list(d.blocks())
        request = blocks[3]
        assert request.axis_exchange == AxisExchange(REQUEST, (1,))
        assert (request.number, request.source.line, request.motion) == (40, 4, None)
        assert request.needs_stop
        assert blocks[4].motion.start_mm == (3.0, 2.0, 0.0)
        assert blocks[4].motion.end_mm == (3.0, 5.0, 0.0)
        assert d.modal.released_axes == frozenset()


def test_request_with_expressions_and_several_axes() -> None:
    d = decoder("#AX RELEASE ALL\n#AX REQUEST [z, 1 + 2, 4 / 2] [X, 1, 0] [X, 1, 0]\nM30")
    blocks = list(d.blocks())
    assert blocks[1].axis_exchange == AxisExchange(REQUEST, (2, 0))
    assert d.modal.released_axes == frozenset({1})


def test_request_by_configured_axis_numbers() -> None:
    program = "#AX RELEASE NBR [12]\n#AX REQUEST [Y, 12, 1]\nG0 Y1\nM30"
    blocks = decode(program, axis_numbers=(11, 12, 13))
    assert [b.axis_exchange for b in blocks[:2]] == [AxisExchange(RELEASE, (1,)),
                                                     AxisExchange(REQUEST, (1,))]
    assert blocks[2].motion.end_mm == (0.0, 1.0, 0.0)


def test_request_of_an_axis_in_the_channel_gives_nothing() -> None:
    blocks = decode("#AX REQUEST [X, 1, 0]\nG0 X1\nM30")
    assert [b.axis_exchange for b in blocks] == [None, None]
    assert blocks[0].motion.end_mm == (1.0, 0.0, 0.0)


@pytest.mark.parametrize(
    ("program", "err", "column", "text"),
    [
        ("#AX REQUEST [Y, 4, 1]", NcErrorId.AXIS_EXCHANGE_NOT_SUPPORTED, 17,
         "axis exchange between channels is not supported: axis 4"),
        ("#AX REQUEST [Y, 2, 0]", NcErrorId.AXIS_EXCHANGE_NOT_SUPPORTED, 20,
         "axis exchange between channels is not supported: axis 2 (Y) has the index 1"),
        ("#AX REQUEST [W, 2, 1]", NcErrorId.AXIS_EXCHANGE_NOT_SUPPORTED, 14,
         "axis exchange between channels is not supported: axis 2 is named Y"),
        ("#AX REQUEST [X, 2, 1]", NcErrorId.AXIS_EXCHANGE_NOT_SUPPORTED, 14,
         "axis name X belongs to axis 1"),
        ("#AX REQUEST [Y, 2, 1] [X, 3, 0]", NcErrorId.AXIS_EXCHANGE_NOT_SUPPORTED, 30,
         "axis 3 (Z) has the index 2"),
        ("#AX REQUEST [Y, 0, 1]", NcErrorId.INVALID_AXIS_NUMBER, 17, "axis number 0"),
        ("#AX REQUEST [Y, 2, -1]", NcErrorId.INVALID_AXIS_NUMBER, 20, "axis index -1"),
        ("#AX REQUEST [Y, 2, 0.5]", NcErrorId.INVALID_AXIS_NUMBER, 20, "axis index 0.5"),
        ("#AX RELEASE NBR [1.5]", NcErrorId.INVALID_AXIS_NUMBER, 18, "axis number 1.5"),
        ('#AX RELEASE NBR ["X"]', NcErrorId.TYPE_MISMATCH, 18, "string"),
    ],
)
def test_request_errors(program, err, column, text) -> None:
    e = error_of("#AX RELEASE [Y]\n" + program + "\nM30")
    assert (e.id, e.line, e.column) == (err, 2, column)
    assert text in e.message


def test_a_failed_request_changes_nothing() -> None:
    d = decoder("#AX RELEASE [X, Y]\n#AX REQUEST [X, 1, 0] [Y, 9, 1]\nM30")
    with pytest.raises(NcError) as info:
        list(d.blocks())
    assert info.value.id == NcErrorId.AXIS_EXCHANGE_NOT_SUPPORTED
    assert d.modal.released_axes == frozenset({0, 1})


# ---------------------------------------------------------------- syntax


@pytest.mark.parametrize(
    ("program", "err", "column"),
    [
        ("#AX RELEASE [X] G1 Y1", NcErrorId.AXIS_COMMAND_NOT_ALONE, 17),
        ("#AX REQUEST [X, 1, 0] M3", NcErrorId.AXIS_COMMAND_NOT_ALONE, 23),
        ("#AX RELEASE ALL #AX RELEASE ALL", NcErrorId.AXIS_COMMAND_NOT_ALONE, 17),
        ("G0 X1 #AX RELEASE [Y]", NcErrorId.AXIS_COMMAND_NOT_ALONE, 7),
        ("M3 # ax REQUEST [X, 1, 0]", NcErrorId.AXIS_COMMAND_NOT_ALONE, 4),
        ("#AX LINK [X]", NcErrorId.INSTRUCTION_NOT_SUPPORTED, 1),
        ("#AX", NcErrorId.INSTRUCTION_NOT_SUPPORTED, 1),
        ("#AX RELEASE", NcErrorId.EXPRESSION_SYNTAX, 12),
        ("#AX RELEASE [X", NcErrorId.EXPRESSION_SYNTAX, 15),
        ("#AX RELEASE [X,]", NcErrorId.EXPRESSION_SYNTAX, 16),
        ("#AX RELEASE NBR []", NcErrorId.EXPRESSION_SYNTAX, 18),
        ("#AX REQUEST [X, 1]", NcErrorId.EXPRESSION_SYNTAX, 18),
        ("#AX REQUEST X, 1, 0", NcErrorId.EXPRESSION_SYNTAX, 13),
    ],
)
def test_syntax_errors(program, err, column) -> None:
    e = error_of("G0 X0\n" + program + "\nM30")
    assert (e.id, e.line, e.column) == (err, 2, column)


def test_number_and_label_may_precede_the_command() -> None:
    blocks = decode("N10 [START] #AX RELEASE [X]\nM30")
    assert blocks[0].axis_exchange == AxisExchange(RELEASE, (0,))
    assert blocks[0].number == 10


def test_check_syntax_reports_misplaced_commands() -> None:
    errors = check_syntax("#AX RELEASE [X]\nG1 X1 #AX REQUEST [X, 1, 0]\n#AX RELEASE [Y] Y1\n",
                          "p.nc", axes=AXES)
    assert [(e.id, e.line, e.column) for e in errors] == [
        (NcErrorId.AXIS_COMMAND_NOT_ALONE, 2, 7), (NcErrorId.AXIS_COMMAND_NOT_ALONE, 3, 17)]


# ---------------------------------------------------------------- program start, MDI


def test_manual_blocks_keep_the_released_axes() -> None:
    modal = ModalState()
    first = decode("#AX RELEASE [Y]", modal=modal, manual=True)
    assert first[0].axis_exchange == AxisExchange(RELEASE, (1,)) and first[0].manual
    e = error_of("G0 Y1", modal=modal, manual=True)  # a plain line: the hot path's kind
    assert (e.id, e.line, e.column, e.message) == (NcErrorId.AXIS_RELEASED, 1, 4, RELEASED_Y)
    assert modal.released_axes == frozenset({1})
    assert decode("G0 X4", modal=modal, manual=True)[0].motion.end_mm == (4.0, 0.0, 0.0)
    blocks = decode("#AX REQUEST [Y, 2, 1]\nG0 Y1", modal=modal, manual=True)
    assert blocks[0].axis_exchange == AxisExchange(REQUEST, (1,))
    assert blocks[1].motion.end_mm == (4.0, 1.0, 0.0)


def test_a_program_start_gives_all_axes_back() -> None:
    modal = ModalState()
    decode("#AX RELEASE ALL", modal=modal, manual=True)
    assert modal.released_axes == frozenset({0, 1, 2})
    blocks = decode("G0 Y1\nM30", modal=modal)
    assert blocks[0].motion.end_mm == (0.0, 1.0, 0.0)
    assert modal.released_axes == frozenset()


def test_a_fresh_decoder_has_all_axes() -> None:
    d = decoder("#AX RELEASE [Z]\nM30")
    list(d.blocks())
    assert d.modal.released_axes == frozenset({2})
    assert decoder("G0 Z1\nM30").modal.released_axes == frozenset()
    assert decode("G0 Z1\nM30")[0].motion.end_mm == (0.0, 0.0, 1.0)


@pytest.mark.parametrize("numbers", [(1, 2), (1, 2, 2), (0, 1, 2), (1, 2, 3.0)])
def test_invalid_axis_numbers(numbers) -> None:
    with pytest.raises(ValueError):
        decoder("M30", axis_numbers=numbers)


def test_released_axes_must_belong_to_the_channel() -> None:
    with pytest.raises(ValueError):
        decoder("G0 X1", modal=ModalState(released_axes=frozenset({3})), manual=True)


def test_hot_and_general_path_agree_around_an_exchange() -> None:
    lines = ["G1 X0 Y0 Z0 F1200"]
    lines += [f"N{k} X{k} Y{k % 7} Z{k % 3}" for k in range(1, 30)]
    lines += ["#AX RELEASE [Z]"] + [f"X{k} Y{k % 5}" for k in range(30, 60)]
    lines += ["#AX REQUEST [Z, 3, 2]", "G2 X61 I1"]
    lines += [f"G1 X{k} Z{k % 4}" for k in range(62, 80)] + ["M30"]
    program = "\n".join(lines)
    fast = decode(program)
    # slow() makes the lines longer: all but the byte offsets must be the same
    assert [replace(b, source=replace(b.source, offset=0)) for b in fast] == [
        replace(b, source=replace(b.source, offset=0)) for b in decode(slow(program))]
    assert len(fast) == 1 + 29 + 1 + 30 + 1 + 1 + 18 + 1
