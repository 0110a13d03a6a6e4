"""Program structure and subprograms: %name, %L / LL, L file, M17/M29, depth, ends."""

from __future__ import annotations

import pytest

from cnc_objects.service.kernel.nc import NcErrorId, StopKind

from .support import decode, ends, error_of

LOCALS = """; local subprograms before the main program
%L UP1           (first local subprogram)
G0 X1
M17
%L UP2
G0 X2            ; ends at the next % line without M17
%MAIN
LL UP1
LL UP2
LL UP3
M30
%L UP3
G0 X3
M29
"""


def test_local_subprograms_before_and_after_the_main_program() -> None:
    blocks = decode(LOCALS)
    assert [b.motion.end_mm[0] for b in blocks if b.motion] == [1.0, 2.0, 3.0]
    assert [b.source.line for b in blocks] == [3, 6, 13, 11]


def test_file_without_header_runs_to_its_first_local_subprogram() -> None:
    assert ends("G0 X5\nLL A\nM30\n%L A\nG0 Y5\n") == [(5, 0, 0), (5, 5, 0)]


def test_file_subprogram_from_the_loader() -> None:
    files = {"sub.nc": "%SUB\nG0 Z9\nLL INNER\nM17\n%L INNER\nG0 Y7\nM17\n"}
    blocks = decode("G0 X1\nL sub.nc\nG0 X2\nM30", files=files)
    assert [b.motion.end_mm for b in blocks if b.motion] == [
        (1, 0, 0), (1, 0, 9), (1, 7, 9), (2, 7, 9)]
    # blocks from the subprogram name their own file and line
    assert [(b.source.file, b.source.line) for b in blocks] == [
        ("prog.nc", 1), ("sub.nc", 2), ("sub.nc", 6), ("prog.nc", 3), ("prog.nc", 4)]


def test_file_subprogram_is_loaded_once() -> None:
    calls = []
    files = {"s.nc": "G91 G0 X1\nG90\nM17"}

    def loader(name):
        calls.append(name)
        return files[name]

    from cnc_objects.service.kernel.nc import Decoder
    program = "$FOR V.P.I = 1, 3\nL s.nc\n$ENDFOR\nM30"
    d = Decoder("#VAR\nV.P.I\n#ENDVAR\n" + program, "p.nc", axes=("X", "Y", "Z"),
                loader=loader, tools={})
    assert [b.motion.end_mm[0] for b in d.blocks() if b.motion] == [1, 2, 3]
    assert calls == ["s.nc"]


def test_error_inside_a_file_subprogram_names_that_file() -> None:
    e = error_of("G0 X1\nL sub.nc\nM30", files={"sub.nc": "G0 X2\n  Q1\nM17"})
    assert (e.id, e.file, e.line, e.column) == (NcErrorId.UNKNOWN_WORD, "sub.nc", 2, 3)


def test_call_and_motion_in_one_block() -> None:
    blocks = decode("G0 X1 LL A\nM30\n%L A\nG0 Y1\n")
    assert [b.motion.end_mm for b in blocks if b.motion] == [(1, 0, 0), (1, 1, 0)]


def test_program_end_inside_a_subprogram_ends_everything() -> None:
    blocks = decode("LL A\nG0 X9\nM30\n%L A\nG0 Y1\nM30\n")
    assert blocks[-1].stop == StopKind.PROGRAM_END
    assert [b.motion.end_mm for b in blocks if b.motion] == [(0, 1, 0)]


def test_recursion_with_an_exit_condition() -> None:
    program = """#VAR
V.P.DEPTH = 0
#ENDVAR
LL REC
M30
%L REC
V.P.DEPTH = V.P.DEPTH + 1
G0 X[V.P.DEPTH]
$IF V.P.DEPTH < 5
LL REC
$ENDIF
M17
"""
    assert [e[0] for e in ends(program)] == [1, 2, 3, 4, 5]


@pytest.mark.parametrize(
    ("program", "files", "err", "file", "line", "column"),
    [
        ("L none.nc\nM30", {}, NcErrorId.FILE_NOT_FOUND, "prog.nc", 1, 1),
        ("G0 X1 L\nM30", {}, NcErrorId.MISSING_VALUE, "prog.nc", 1, 7),
        ("LL NOPE\nM30", {}, NcErrorId.SUBPROGRAM_NOT_FOUND, "prog.nc", 1, 1),
        ("LL A\nM30\n%L A\nM17\n%L A\nM17", {}, NcErrorId.DUPLICATE_SUBPROGRAM, "prog.nc", 1, 1),
        ("LL A\nM30\n%L A\nLL A\n", {}, NcErrorId.CALL_DEPTH_EXCEEDED, "prog.nc", 4, 1),
        ("L s.nc\nM30", {"s.nc": "L s.nc\nM17"}, NcErrorId.CALL_DEPTH_EXCEEDED, "s.nc", 1, 1),
        ("L s.nc\nM30", {"s.nc": "G0 X1\n"}, NcErrorId.SUBPROGRAM_END_MISSING, "s.nc", 1, 1),
        ("L s.nc\nM30", {"s.nc": "LL NOPE\nM17"}, NcErrorId.SUBPROGRAM_NOT_FOUND, "s.nc", 1, 1),
        ("G0 X1\n%L A\nM17\n", {}, NcErrorId.MISSING_PROGRAM_END, "prog.nc", 1, 1),
        ("%MAIN\nG0 X1\n", {}, NcErrorId.MISSING_PROGRAM_END, "prog.nc", 2, 1),
        ("L CYCLE [NAME=x.ecy @P1=1]\nM30", {}, NcErrorId.CYCLE_NOT_FOUND, "prog.nc", 1, 15),
        ("LL CYCLE [NAME=x.ecy]\nM30", {}, NcErrorId.CYCLE_NOT_FOUND, "prog.nc", 1, 16),
        ("LL cycle\nM30", {}, NcErrorId.SUBPROGRAM_NOT_FOUND, "prog.nc", 1, 1),
        ("LL A\nM30\n%L A\n$IF 1\n", {}, NcErrorId.BLOCK_NOT_CLOSED, "prog.nc", 4, 1),
        ("$GOTO [X]\nM30\n%L A\n[X] G0 X1\nM17", {}, NcErrorId.LABEL_NOT_FOUND, "prog.nc", 1, 1),
    ],
)
def test_structure_errors(program, files, err, file, line, column) -> None:
    e = error_of(program, files=files)
    assert (e.id, e.file, e.line, e.column) == (err, file, line, column), str(e)


def test_m17_inside_an_if_block_ends_the_subprogram() -> None:
    assert ends("LL A\nM30\n%L A\n$IF 1\nG0 X1\nM17\n$ENDIF\n") == [(1, 0, 0)]


def test_recursion_never_overflows_pythons_stack() -> None:
    e = error_of("LL R\nM30\n%L R\nG0 X1\nLL R\n")
    assert e.id == NcErrorId.CALL_DEPTH_EXCEEDED
