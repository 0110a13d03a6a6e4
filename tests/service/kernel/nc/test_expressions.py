"""Expressions: operators, precedence, functions, comparisons, logic, errors."""

from __future__ import annotations

import math

import pytest

from cnc_objects.service.kernel.nc import NcErrorId

from .support import decode, error_of


def value(expr: str) -> float:
    """The value of ``expr`` as an X word (Y1 makes sure the block moves)."""
    return decode(f"G0 Y1 X[{expr}]\nM30")[0].motion.end_mm[0]


@pytest.mark.parametrize(
    ("expr", "expected"),
    [
        ("1 + 2 * 3", 7), ("[1 + 2] * 3", 9), ("10 - 4 - 3", 3), ("2 ** 3 ** 2", 512),
        ("2 ^ 3", 8), ("-2 ** 2", -4), ("-[2]", -2), ("--3", 3), ("+3", 3),
        ("7 / 2", 3.5), ("7 MOD 3", 1), ("-7 MOD 3", -1), ("7.5 MOD 2", 1.5),
        ("ABS[-3]", 3), ("SQRT[16]", 4), ("SQR[3]", 9), ("SIN[30]", 0.5), ("COS[60]", 0.5),
        ("TAN[45]", 1), ("ASIN[1]", 90), ("ACOS[0]", 90), ("ATAN[1]", 45),
        ("ATAN2[1, 1]", 45), ("EXP[0]", 1), ("LN[EXP[2]]", 2), ("INT[2.7]", 2),
        ("INT[-2.7]", -2), ("ROUND[2.5]", 3), ("ROUND[-2.5]", -3), ("ROUND[2.4]", 2),
        ("FRACT[2.75]", 0.75), ("FRACT[-2.75]", -0.75),
        ("1 == 1", 1), ("1 != 1", 0), ("1 <> 2", 1), ("1 < 2", 1), ("2 <= 2", 1),
        ("3 > 4", 0), ("3 >= 4", 0), ("1 + 1 == 2", 1),
        ("TRUE AND FALSE", 0), ("TRUE OR FALSE", 1), ("NOT FALSE", 1), ("NOT 1 == 2", 1),
        ("1 XOR 1", 0), ("1 XOR 0", 1), ("1 < 2 AND 2 < 3", 1), ("0 OR 0 OR 5", 1),
        ("true", 1), ("false + 2", 2), ("sin[90] * 4", 4), ("2*[3+[4-1]]", 12),
        ("1 + " * 200 + "1", 201),  # a long chain does not nest Python calls
        ('"ab" == "ab"', 1), ('"ab" != "ac"', 1),
    ],
)
def test_values(expr, expected) -> None:
    assert value(expr) == pytest.approx(expected, abs=1e-12)


def test_short_circuit_skips_errors() -> None:
    assert value("0 AND 1/0") == 0
    assert value("1 OR 1/0") == 1


@pytest.mark.parametrize(
    ("expr", "err", "column"),
    [
        # column of the offending operator / function / token in "G0 Y1 X[<expr>]"
        ("1 / 0", NcErrorId.DIVISION_BY_ZERO, 11),
        ("1 MOD 0", NcErrorId.DIVISION_BY_ZERO, 11),
        ("SQRT[-1]", NcErrorId.MATH_DOMAIN, 9),
        ("LN[0]", NcErrorId.MATH_DOMAIN, 9),
        ("ASIN[2]", NcErrorId.MATH_DOMAIN, 9),
        ("EXP[1000]", NcErrorId.MATH_DOMAIN, 9),
        ("10 ** 400", NcErrorId.MATH_DOMAIN, 12),
        ("[-8] ** 0.5", NcErrorId.MATH_DOMAIN, 14),
        ("FOO[1]", NcErrorId.UNKNOWN_FUNCTION, 9),
        ("ATAN2[1]", NcErrorId.EXPRESSION_SYNTAX, 9),
        ("1 +", NcErrorId.EXPRESSION_SYNTAX, 12),
        ("[1 + 2", NcErrorId.EXPRESSION_SYNTAX, 16),
        ("1 2", NcErrorId.EXPRESSION_SYNTAX, 11),
        ("PI", NcErrorId.EXPRESSION_SYNTAX, 9),
        ('"a" + 1', NcErrorId.TYPE_MISMATCH, 13),
        ('"a" < "b"', NcErrorId.TYPE_MISMATCH, 13),
        ('"a"', NcErrorId.TYPE_MISMATCH, 8),
        ('"abc', NcErrorId.STRING_NOT_CLOSED, 9),
        ("[" * 40 + "1" + "]" * 40, NcErrorId.EXPRESSION_TOO_COMPLEX, 41),
        ("-" * 100 + "1", NcErrorId.EXPRESSION_TOO_COMPLEX, 41),
        ("1e10 ** 40", NcErrorId.EXPRESSION_SYNTAX, 10),
    ],
)
def test_expression_errors(expr, err, column) -> None:
    e = error_of(f"G0 Y1 X[{expr}]\nM30")
    assert (e.id, e.line, e.column) == (err, 1, column), str(e)


def test_division_by_zero_message() -> None:
    assert error_of("G0 X[1/0]\nM30").message == "division by zero"


def test_infinite_result_is_out_of_range() -> None:
    e = error_of("G0 X[1E300]\nM30")
    assert e.id == NcErrorId.EXPRESSION_SYNTAX
    e = error_of("G0 X[10**300 * 10**300]\nM30")
    assert (e.id, e.column) == (NcErrorId.VALUE_OUT_OF_RANGE, 4)
    assert math.isinf(10.0**300 * 10.0**300)


@pytest.mark.parametrize(
    ("expr", "err"),
    [
        ("[10**300 * 10**300] MOD 3", NcErrorId.MATH_DOMAIN),
        ("INT[10**300 * 10**300]", NcErrorId.MATH_DOMAIN),
        ("ROUND[[10**300 * 10**300] - [10**300 * 10**300]]", NcErrorId.MATH_DOMAIN),
    ],
)
def test_infinite_intermediate_values(expr, err) -> None:
    assert error_of(f"G0 X[{expr}]\nM30").id == err


def test_infinite_array_index() -> None:
    e = error_of("#VAR\nV.L.A[2]\n#ENDVAR\nG0 X[V.L.A[10**300 * 10**300]]\nM30")
    assert e.id == NcErrorId.ARRAY_INDEX_MISMATCH
