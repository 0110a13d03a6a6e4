"""Variables: #VAR declarations, types, arrays, scopes, assignments, errors."""

from __future__ import annotations

import pytest

from cnc_objects.service.kernel.nc import ModalState, NcError, NcErrorId

from .support import decode, decoder, ends, error_of


def xs(program: str, **kw) -> list[float]:
    """X of every motion end point."""
    return [e[0] for e in ends(program, **kw)]


def test_declarations_types_and_initial_values() -> None:
    program = """
#VAR
  V.L.A                     ; REAL64, 0.0
  V.L.B : UNS32 = 200
  V.L.C : REAL64 = 11.34
  V.L.D : BOOLEAN
  V.L.E = 10
  V.L.F : SGN32 = -2.5      ; rounds half away from zero
  V.L.S : STRING = "abc"
#ENDVAR
G0 Y1 X[V.L.A]
X[V.L.B]
X[V.L.C]
X[V.L.D]
X[V.L.E]
X[V.L.F]
$IF V.L.S == "abc"
X77
$ENDIF
M30
"""
    assert xs(program) == [0.0, 200.0, 11.34, 0.0, 10.0, -3.0, 77.0]


def test_arrays_and_initializer_lists() -> None:
    program = """
#VAR
  V.L.A[3] = [1, 2, 3]
  V.L.B[4] : SGN32 = [5, 6]
  V.L.M[2][2] = [[1, 2], [3, 4]]
  V.L.L = [3,
      212, 213]
#ENDVAR
G0 Y1 X[V.L.A[0] + V.L.A[2]]
X[V.L.B[1] + V.L.B[3]]
X[V.L.M[1][0]]
X[V.L.L[1]]
V.L.A[1] = 40
X[V.L.A[1]]
M30
"""
    assert xs(program) == [4.0, 6.0, 3.0, 212.0, 40.0]


def test_axis_word_with_a_variable_directly_after_the_letter() -> None:
    program = "#VAR\nV.L.P = 10\n#ENDVAR\nG0 XV.L.P Y-V.L.P Z-[V.L.P * 2]\nM30"
    assert ends(program) == [(10.0, -10.0, -20.0)]


def test_assignments_run_left_to_right_in_a_block() -> None:
    program = "#VAR\nV.L.P = 1\n#ENDVAR\nV.L.P = 5 G0 X[V.L.P] V.L.P = 7 Y[V.L.P]\nM30"
    assert ends(program) == [(5.0, 7.0, 0.0)]


def test_local_variables_belong_to_their_program() -> None:
    program = """%MAIN
#VAR
V.L.A = 1
#ENDVAR
LL SUB
G0 X[V.L.A]
M30
%L SUB
#VAR
V.L.A = 50
#ENDVAR
G0 Y[V.L.A]
M17
"""
    assert ends(program) == [(0.0, 50.0, 0.0), (1.0, 50.0, 0.0)]


def test_program_globals_are_visible_in_subprograms() -> None:
    program = "#VAR\nV.P.COUNT = 0\n#ENDVAR\nLL INC\nLL INC\nG0 X[V.P.COUNT]\nM30\n" \
              "%L INC\nV.P.COUNT = V.P.COUNT + 1\nM17"
    assert xs(program) == [2.0]


def test_cycle_variables_are_visible_in_called_programs() -> None:
    files = {"calc.nc": "V.CYC.RESULT = 42\nM17\n"}
    program = "#VAR\nV.CYC.RESULT\n#ENDVAR\nL calc.nc\nG0 X[V.CYC.RESULT]\nM30"
    assert xs(program, files=files) == [42.0]


def test_globals_live_in_the_modal_state() -> None:
    modal = ModalState()
    decode("#VAR\nV.G.TOTAL = 3\n#ENDVAR\nV.G.TOTAL = V.G.TOTAL + 1\nM30", modal=modal)
    # a second program: declaring it again keeps the value
    blocks = decode("#VAR\nV.G.TOTAL = 0\n#ENDVAR\nG0 X[V.G.TOTAL]\nM30", modal=modal)
    assert blocks[0].motion.end_mm[0] == 4.0


def test_program_variables_continue_in_manual_blocks() -> None:
    modal = ModalState()
    decode("#VAR\nV.P.N = 1\n#ENDVAR", modal=modal, manual=True)
    decode("V.P.N = V.P.N + 1", modal=modal, manual=True)
    blocks = decode("G0 X[V.P.N]", modal=modal, manual=True)
    assert blocks[0].motion.end_mm[0] == 2.0
    # a new program may declare it again
    blocks = decode("#VAR\nV.P.N = 9\n#ENDVAR\nG0 X[V.P.N]\nM30", modal=modal)
    assert blocks[0].motion.end_mm[0] == 9


def test_declaration_in_a_loop_reinitialises() -> None:
    program = "$FOR V.P.I = 1, 3\n#VAR\nV.L.X = 0\n#ENDVAR\nV.L.X = V.L.X + V.P.I\n" \
              "G0 X[V.L.X] Y[V.P.I]\n$ENDFOR\nM30"
    d = decoder(program)
    d.modal.variables_p.clear()
    with pytest.raises(NcError):  # V.P.I is not declared
        list(d.blocks())
    program = "#VAR\nV.P.I\n#ENDVAR\n" + program
    assert xs(program) == [1.0, 2.0, 3.0]


@pytest.mark.parametrize(
    ("program", "err", "line", "column"),
    [
        ("G0 X[V.L.NOPE]\nM30", NcErrorId.UNDECLARED_VARIABLE, 1, 6),
        ("V.L.NOPE = 1\nM30", NcErrorId.UNDECLARED_VARIABLE, 1, 1),
        ("#VAR\nV.L.A\nV.L.A\n#ENDVAR\nM30", NcErrorId.VARIABLE_DECLARED_TWICE, 3, 1),
        ("#VAR\nV.L.A : FLOAT\n#ENDVAR\nM30", NcErrorId.UNKNOWN_TYPE, 2, 9),
        ("#VAR\nV.L.A : UNS32 = -1\n#ENDVAR\nM30", NcErrorId.VALUE_OUT_OF_TYPE_RANGE, 2, 1),
        ("#VAR\nV.L.A : UNS32\n#ENDVAR\nV.L.A = 2 ** 40\nM30",
         NcErrorId.VALUE_OUT_OF_TYPE_RANGE, 4, 1),
        ("#VAR\nV.L.A[2]\n#ENDVAR\nG0 X[V.L.A[2]]\nM30", NcErrorId.ARRAY_INDEX_OUT_OF_RANGE, 4, 6),
        ("#VAR\nV.L.A[2]\n#ENDVAR\nG0 X[V.L.A]\nM30", NcErrorId.ARRAY_INDEX_MISMATCH, 4, 6),
        ("#VAR\nV.L.A\n#ENDVAR\nG0 X[V.L.A[0]]\nM30", NcErrorId.ARRAY_INDEX_MISMATCH, 4, 6),
        ("#VAR\nV.L.A[2]\n#ENDVAR\nG0 X[V.L.A[0.5]]\nM30", NcErrorId.ARRAY_INDEX_MISMATCH, 4, 6),
        ("#VAR\nV.L.A[2] = [1, 2, 3]\n#ENDVAR\nM30", NcErrorId.INVALID_DECLARATION, 2, 1),
        ("#VAR\nV.L.A[2] = 5\n#ENDVAR\nM30", NcErrorId.INVALID_DECLARATION, 2, 1),
        ("#VAR\nG0 X1\n#ENDVAR\nM30", NcErrorId.INVALID_DECLARATION, 2, 1),
        ("#VAR\nV.L.A\n", NcErrorId.VAR_BLOCK_NOT_CLOSED, 1, 1),
        ("#ENDVAR\nM30", NcErrorId.ENDVAR_WITHOUT_VAR, 1, 1),
        ("#VAR\nV.E.A\n#ENDVAR\nM30", NcErrorId.VARIABLE_SCOPE_NOT_ALLOWED, 2, 1),
        ("G0 X[V.E.A]\nM30", NcErrorId.UNKNOWN_VARIABLE, 1, 6),
        ("G0 X[V.P.G[1].POS]\nM30", NcErrorId.INSTRUCTION_NOT_SUPPORTED, 1, 6),
        ("#VAR\nV.L.S : STRING\n#ENDVAR\nV.L.S = 1\nM30", NcErrorId.TYPE_MISMATCH, 4, 1),
        ("#VAR\nV.L.S\n#ENDVAR\nV.L.S = \"x\"\nM30", NcErrorId.TYPE_MISMATCH, 4, 1),
        ("#VAR\nV.L.A\n#ENDVAR\nV.L.A == 1\nM30", NcErrorId.EXPRESSION_SYNTAX, 4, 1),
        ("LL S\nM30\n%L S\n#VAR\nV.P.X\n#ENDVAR\nM17", NcErrorId.VARIABLE_SCOPE_NOT_ALLOWED, 5, 1),
    ],
)
def test_variable_errors(program, err, line, column) -> None:
    e = error_of(program)
    assert (e.id, e.line, e.column) == (err, line, column), str(e)


def test_undeclared_variable_message() -> None:
    assert error_of("G0 X[V.L.X]\nM30").message == "undeclared variable V.L.X"
