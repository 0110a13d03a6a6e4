"""ISG data types (protocol/datatypes.py): sizes, little-endian bytes, limits, strings, parsing.

A value crosses the wire as the bytes the CNC keeps in memory, so each type is checked
against hand-written byte strings, its limits and the Python types it refuses; the
round trips are properties over every value the type can hold.
"""

from __future__ import annotations

import math
import struct

import pytest
from hypothesis import given
from hypothesis import strategies as st

from cnc_objects.protocol.datatypes import (
    BOOLEAN,
    REAL32,
    REAL64,
    SCALAR_TYPES,
    SGN08,
    SGN16,
    SGN32,
    SGN64,
    STRING,
    UNS08,
    UNS16,
    UNS32,
    UNS64,
    DataType,
    fit_string,
    parse_type,
    parse_value,
)

#: (type, size in bytes, IEC name, minimum, maximum) of every integer type.
INTEGERS = [
    (UNS08, 1, "USINT", 0, 0xFF),
    (SGN08, 1, "SINT", -0x80, 0x7F),
    (UNS16, 2, "UINT", 0, 0xFFFF),
    (SGN16, 2, "INT", -0x8000, 0x7FFF),
    (UNS32, 4, "UDINT", 0, 0xFFFF_FFFF),
    (SGN32, 4, "DINT", -0x8000_0000, 0x7FFF_FFFF),
    (UNS64, 8, "ULINT", 0, 0xFFFF_FFFF_FFFF_FFFF),
    (SGN64, 8, "LINT", -0x8000_0000_0000_0000, 0x7FFF_FFFF_FFFF_FFFF),
]
INTEGER_IDS = [t.name for t, *_ in INTEGERS]

#: Every fixed-size scalar type with its size, as the ISG tables give it.
SIZES = {
    "BOOLEAN": 1,
    "UNS08": 1,
    "SGN08": 1,
    "UNS16": 2,
    "SGN16": 2,
    "UNS32": 4,
    "SGN32": 4,
    "UNS64": 8,
    "SGN64": 8,
    "REAL32": 4,
    "REAL64": 8,
}

REAL32_MAX = 3.4028234663852886e38

#: Characters CP1252 can encode, except NUL (the terminator).
cp1252_text = st.text(alphabet=st.characters(codec="cp1252", exclude_characters="\x00"))


# --------------------------------------------------------------------------- sizes


@pytest.mark.parametrize(("name", "size"), sorted(SIZES.items()))
def test_every_scalar_type_has_its_isg_size(name: str, size: int) -> None:
    dtype = SCALAR_TYPES[name]
    assert dtype.name == name
    assert dtype.size == size


def test_the_scalar_table_holds_exactly_the_isg_types() -> None:
    assert set(SCALAR_TYPES) == set(SIZES)


@pytest.mark.parametrize(
    ("dtype", "iec"),
    [(BOOLEAN, "BOOL"), (REAL32, "REAL"), (REAL64, "LREAL"), (STRING(84), "STRING")]
    + [(t, iec) for t, _, iec, _, _ in INTEGERS],
    ids=lambda v: v.name if isinstance(v, DataType) else v,
)
def test_iec_names(dtype: DataType, iec: str) -> None:
    assert dtype.iec == iec


@pytest.mark.parametrize("dtype", list(SCALAR_TYPES.values()), ids=list(SCALAR_TYPES))
def test_encode_gives_exactly_size_bytes(dtype: DataType) -> None:
    value = {"bool": True, "int": 1, "float": 1.5}[dtype.kind]
    assert len(dtype.encode(value)) == dtype.size


# --------------------------------------------------------------------------- BOOLEAN


@pytest.mark.parametrize(
    ("value", "raw"), [(True, b"\x01"), (False, b"\x00"), (1, b"\x01"), (0, b"\x00")]
)
def test_boolean_encodes_one_byte(value: object, raw: bytes) -> None:
    assert BOOLEAN.encode(value) == raw


@pytest.mark.parametrize(("raw", "value"), [(b"\x00", False), (b"\x01", True)])
def test_boolean_decodes(raw: bytes, value: bool) -> None:
    assert BOOLEAN.decode(raw) is value


@pytest.mark.parametrize("value", [2, -1])
def test_boolean_refuses_integers_outside_zero_and_one_with_value_error(value: int) -> None:
    # The module's contract: a value of the right Python type outside the type's range
    # is a ValueError; BOOLEAN takes the integers 0 and 1.
    with pytest.raises(ValueError):
        BOOLEAN.encode(value)


@pytest.mark.parametrize("value", ["1", "true", 1.0, None, b"\x01"])
def test_boolean_refuses_other_python_types(value: object) -> None:
    with pytest.raises(TypeError):
        BOOLEAN.encode(value)


@pytest.mark.parametrize("raw", [b"", b"\x00\x00"])
def test_boolean_decode_refuses_wrong_length(raw: bytes) -> None:
    with pytest.raises(ValueError):
        BOOLEAN.decode(raw)


# --------------------------------------------------------------------------- integers


@pytest.mark.parametrize(
    ("dtype", "value", "raw"),
    [
        (UNS08, 0xAB, b"\xab"),
        (SGN08, -1, b"\xff"),
        (SGN08, -128, b"\x80"),
        (UNS16, 0x1234, b"\x34\x12"),
        (SGN16, -2, b"\xfe\xff"),
        (UNS32, 0x12345678, b"\x78\x56\x34\x12"),
        (SGN32, -0x12345678, b"\x88\xa9\xcb\xed"),
        (UNS64, 0x0102030405060708, b"\x08\x07\x06\x05\x04\x03\x02\x01"),
        (SGN64, -2, b"\xfe\xff\xff\xff\xff\xff\xff\xff"),
    ],
    ids=lambda v: v.name if isinstance(v, DataType) else None,
)
def test_integers_are_little_endian(dtype: DataType, value: int, raw: bytes) -> None:
    assert dtype.encode(value) == raw
    assert dtype.decode(raw) == value


@pytest.mark.parametrize(("dtype", "size", "iec", "lo", "hi"), INTEGERS, ids=INTEGER_IDS)
def test_integer_limits_are_accepted(
    dtype: DataType, size: int, iec: str, lo: int, hi: int
) -> None:
    assert (dtype.minimum, dtype.maximum) == (lo, hi)
    assert dtype.decode(dtype.encode(lo)) == lo
    assert dtype.decode(dtype.encode(hi)) == hi


@pytest.mark.parametrize(("dtype", "size", "iec", "lo", "hi"), INTEGERS, ids=INTEGER_IDS)
def test_integer_limit_bytes(dtype: DataType, size: int, iec: str, lo: int, hi: int) -> None:
    if lo == 0:
        assert dtype.encode(lo) == b"\x00" * size
        assert dtype.encode(hi) == b"\xff" * size
    else:
        assert dtype.encode(lo) == b"\x00" * (size - 1) + b"\x80"
        assert dtype.encode(hi) == b"\xff" * (size - 1) + b"\x7f"


@pytest.mark.parametrize(("dtype", "size", "iec", "lo", "hi"), INTEGERS, ids=INTEGER_IDS)
def test_integer_one_past_a_limit_is_a_value_error(
    dtype: DataType, size: int, iec: str, lo: int, hi: int
) -> None:
    with pytest.raises(ValueError):
        dtype.encode(lo - 1)
    with pytest.raises(ValueError):
        dtype.encode(hi + 1)


@pytest.mark.parametrize("dtype", [t for t, *_ in INTEGERS], ids=INTEGER_IDS)
@pytest.mark.parametrize("value", [True, False, 1.0, "1", None, b"\x01"], ids=repr)
def test_integers_refuse_other_python_types(dtype: DataType, value: object) -> None:
    # bool is a subclass of int in Python, but not an integer for the CNC.
    with pytest.raises(TypeError):
        dtype.encode(value)


@pytest.mark.parametrize(("dtype", "size", "iec", "lo", "hi"), INTEGERS, ids=INTEGER_IDS)
def test_integer_decode_refuses_wrong_length(
    dtype: DataType, size: int, iec: str, lo: int, hi: int
) -> None:
    with pytest.raises(ValueError):
        dtype.decode(b"\x00" * (size - 1))
    with pytest.raises(ValueError):
        dtype.decode(b"\x00" * (size + 1))


@given(data=st.data())
@pytest.mark.parametrize(("dtype", "size", "iec", "lo", "hi"), INTEGERS, ids=INTEGER_IDS)
def test_integer_round_trip(
    dtype: DataType, size: int, iec: str, lo: int, hi: int, data: st.DataObject
) -> None:
    value = data.draw(st.integers(min_value=lo, max_value=hi))
    raw = dtype.encode(value)
    assert len(raw) == size
    assert int.from_bytes(raw, "little", signed=lo < 0) == value
    assert dtype.decode(raw) == value


# --------------------------------------------------------------------------- reals


@pytest.mark.parametrize(
    ("dtype", "value", "raw"),
    [
        (REAL32, 1.0, b"\x00\x00\x80\x3f"),
        (REAL32, -2.0, b"\x00\x00\x00\xc0"),
        (REAL64, 1.0, b"\x00\x00\x00\x00\x00\x00\xf0\x3f"),
        (REAL64, -2.5, b"\x00\x00\x00\x00\x00\x00\x04\xc0"),
        (REAL64, 3, b"\x00\x00\x00\x00\x00\x00\x08\x40"),
    ],
    ids=lambda v: v.name if isinstance(v, DataType) else None,
)
def test_reals_are_little_endian_ieee754(dtype: DataType, value: float, raw: bytes) -> None:
    assert dtype.encode(value) == raw
    assert dtype.decode(raw) == value


def test_real32_limits() -> None:
    assert REAL32.decode(REAL32.encode(REAL32_MAX)) == REAL32_MAX
    assert REAL32.decode(REAL32.encode(-REAL32_MAX)) == -REAL32_MAX
    past = math.nextafter(REAL32_MAX, math.inf) * 2
    with pytest.raises(ValueError):
        REAL32.encode(past)
    with pytest.raises(ValueError):
        REAL32.encode(-past)
    with pytest.raises(ValueError):
        REAL32.encode(1e39)


def test_real64_limits() -> None:
    biggest = struct.unpack("<d", b"\xff\xff\xff\xff\xff\xff\xef\x7f")[0]
    assert REAL64.decode(REAL64.encode(biggest)) == biggest
    assert REAL64.decode(REAL64.encode(-biggest)) == -biggest


@pytest.mark.parametrize("dtype", [REAL32, REAL64], ids=lambda t: t.name)
def test_reals_refuse_integers_beyond_their_range_with_value_error(dtype: DataType) -> None:
    # Integers are numbers to a REAL; one that no float can hold is out of range.
    with pytest.raises(ValueError):
        dtype.encode(2**1024)


@pytest.mark.parametrize("dtype", [REAL32, REAL64], ids=lambda t: t.name)
def test_reals_accept_infinities_and_nan(dtype: DataType) -> None:
    assert dtype.decode(dtype.encode(math.inf)) == math.inf
    assert dtype.decode(dtype.encode(-math.inf)) == -math.inf
    assert math.isnan(dtype.decode(dtype.encode(math.nan)))


@pytest.mark.parametrize("dtype", [REAL32, REAL64], ids=lambda t: t.name)
@pytest.mark.parametrize("value", [True, False, "1.0", None, b"\x00" * 8], ids=repr)
def test_reals_refuse_other_python_types(dtype: DataType, value: object) -> None:
    with pytest.raises(TypeError):
        dtype.encode(value)


@pytest.mark.parametrize("dtype", [REAL32, REAL64], ids=lambda t: t.name)
def test_real_decode_refuses_wrong_length(dtype: DataType) -> None:
    with pytest.raises(ValueError):
        dtype.decode(b"\x00" * (dtype.size - 1))
    with pytest.raises(ValueError):
        dtype.decode(b"\x00" * (dtype.size + 1))


@given(st.floats(allow_nan=False, allow_infinity=False))
def test_real64_round_trip(value: float) -> None:
    raw = REAL64.encode(value)
    assert len(raw) == 8
    assert REAL64.decode(raw) == value


@given(st.floats(width=32, allow_nan=False, allow_infinity=False))
def test_real32_round_trip_of_single_precision_values(value: float) -> None:
    raw = REAL32.encode(value)
    assert len(raw) == 4
    assert REAL32.decode(raw) == value


# --------------------------------------------------------------------------- STRING(n)


def test_string_is_cp1252_nul_padded_to_its_size() -> None:
    assert STRING(8).encode("Grüß") == b"Gr\xfc\xdf\x00\x00\x00\x00"
    assert STRING(4).encode("€") == b"\x80\x00\x00\x00"
    assert STRING(1).encode("") == b"\x00"


def test_string_size_includes_the_terminator() -> None:
    dtype = STRING(5)
    assert dtype.size == 5
    assert dtype.name == "STRING(5)"
    assert dtype.encode("abcd") == b"abcd\x00"
    with pytest.raises(ValueError):
        dtype.encode("abcde")


def test_string_refuses_nul_inside() -> None:
    with pytest.raises(ValueError):
        STRING(16).encode("ab\x00cd")


def test_string_refuses_characters_cp1252_cannot_encode() -> None:
    with pytest.raises(ValueError):
        STRING(16).encode("\u4e2d")


@pytest.mark.parametrize("value", [b"abc", 12, None, ["a"]], ids=repr)
def test_string_refuses_other_python_types(value: object) -> None:
    with pytest.raises(TypeError):
        STRING(16).encode(value)


@pytest.mark.parametrize(("text", "size", "fitted"), [
    ("G1 X1", 256, "G1 X1"),  # what fits is kept as it is
    ("unknown word '\x00'", 256, "unknown word '?'"),
    ("unknown word '\u0fc2'", 256, "unknown word '?'"),
    ("y" * 300, 256, "y" * 254 + "\u2026"),  # 255 bytes, the last one the ellipsis
    ("abcd", 5, "abcd"),
    ("abcde", 5, "abc\u2026"),
    ("abc", 1, ""),
])
def test_a_kernel_text_is_fitted_to_its_string_buffer(text: str, size: int, fitted: str) -> None:
    assert fit_string(text, size) == fitted
    STRING(size).encode(fitted)  # and encodes


def test_a_kernel_text_is_encoded_fitted_where_encode_refuses_it() -> None:
    """What a read of a kernel text answers: the fitted text, NUL-padded to the size."""
    assert STRING(8).encode_fitted("a\x00b") == b"a?b\x00\x00\x00\x00\x00"
    assert STRING(5).encode_fitted("abcdef") == b"abc\x85\x00"
    with pytest.raises(ValueError):
        STRING(5).encode("abcdef")


@given(st.text(max_size=400), st.integers(1, 300))
def test_every_fitted_text_encodes(text: str, size: int) -> None:
    STRING(size).encode(fit_string(text, size))


def test_string_decode_stops_at_the_first_nul() -> None:
    assert STRING(8).decode(b"ab\x00cd\x00\x00\x00") == "ab"
    assert STRING(4).decode(b"\x00xyz") == ""


def test_string_decode_of_a_full_buffer_without_nul() -> None:
    assert STRING(4).decode(b"abcd") == "abcd"


def test_string_decode_is_cp1252() -> None:
    assert STRING(4).decode(b"\x80\xe4\x00\x00") == "€ä"


@pytest.mark.parametrize("raw", [b"abc", b"abcde\x00"])
def test_string_decode_refuses_wrong_length(raw: bytes) -> None:
    with pytest.raises(ValueError):
        STRING(4).decode(raw)


@pytest.mark.parametrize("size", [0, -1, 65537])
def test_string_size_out_of_range_is_refused(size: int) -> None:
    with pytest.raises(ValueError):
        STRING(size)


def test_string_types_of_one_size_are_one_object() -> None:
    assert STRING(84) is STRING(84)
    assert STRING(84) != STRING(85)


@given(cp1252_text, st.integers(min_value=0, max_value=40))
def test_string_round_trip(value: str, spare: int) -> None:
    dtype = STRING(len(value.encode("cp1252")) + 1 + spare)
    raw = dtype.encode(value)
    assert len(raw) == dtype.size
    assert raw.endswith(b"\x00")
    assert dtype.decode(raw) == value


# --------------------------------------------------------------------------- parse_type


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("uns16", UNS16),
        ("UNS16", UNS16),
        ("Real64", REAL64),
        ("  sgn32 ", SGN32),
        ("boolean", BOOLEAN),
        ("STRING(84)", STRING(84)),
        ("string(32)", STRING(32)),
    ],
)
def test_parse_type(text: str, expected: DataType) -> None:
    assert parse_type(text) is expected


@pytest.mark.parametrize("name", list(SCALAR_TYPES))
def test_parse_type_knows_every_scalar_name(name: str) -> None:
    assert parse_type(name) is SCALAR_TYPES[name]


@pytest.mark.parametrize(
    "text",
    ["", "UNS128", "uint16", "BOOL", "STRING", "STRING()", "STRING(x)", "STRING(-1)",
     "STRING(0)", "STRING(70000)", "UNS16 UNS16"],
)
def test_parse_type_refuses_unknown_names(text: str) -> None:
    with pytest.raises(ValueError):
        parse_type(text)


# --------------------------------------------------------------------------- parse_value


@pytest.mark.parametrize(
    ("dtype", "text", "expected"),
    [
        (UNS16, "4660", 4660),
        (UNS16, "0x1234", 0x1234),
        (UNS16, "0X1f", 0x1F),
        (SGN32, "-17", -17),
        (SGN32, " 42 ", 42),
        (UNS32, "0", 0),
        (UNS08, "007", 7),
    ],
)
def test_parse_value_integers_in_decimal_or_hex(dtype: DataType, text: str, expected: int) -> None:
    value = parse_value(dtype, text)
    assert value == expected
    assert type(value) is int


@pytest.mark.parametrize(
    ("text", "expected"),
    [("true", True), ("TRUE", True), ("1", True), (" True ", True),
     ("false", False), ("False", False), ("0", False)],
)
def test_parse_value_booleans(text: str, expected: bool) -> None:
    assert parse_value(BOOLEAN, text) is expected


@pytest.mark.parametrize("text", ["yes", "no", "on", "off", "Y", "t"])
def test_parse_value_booleans_are_only_what_the_message_lists(text: str) -> None:
    with pytest.raises(ValueError) as caught:
        parse_value(BOOLEAN, text)
    assert str(caught.value) == f"{text!r} is not a boolean (0/1/true/false)"


@pytest.mark.parametrize(
    ("dtype", "text", "expected"),
    [(REAL64, "1.5", 1.5), (REAL64, "-2", -2.0), (REAL64, "1e3", 1000.0), (REAL32, " 0.25 ", 0.25)],
)
def test_parse_value_reals(dtype: DataType, text: str, expected: float) -> None:
    value = parse_value(dtype, text)
    assert value == expected
    assert type(value) is float


def test_parse_value_strings_are_taken_as_given() -> None:
    assert parse_value(STRING(16), " x y ") == " x y "


@pytest.mark.parametrize(
    ("dtype", "text"),
    [
        (UNS16, "twelve"),
        (UNS16, ""),
        (UNS16, "1.5"),
        (UNS16, "0xZZ"),
        (BOOLEAN, "2"),
        (BOOLEAN, "maybe"),
        (BOOLEAN, ""),
        (REAL64, "one"),
        (REAL64, ""),
        (REAL32, "1,5"),
    ],
)
def test_parse_value_refuses_bad_text(dtype: DataType, text: str) -> None:
    with pytest.raises(ValueError):
        parse_value(dtype, text)


@given(st.integers(min_value=0, max_value=0xFFFF))
def test_parse_value_reads_what_decimal_and_hex_print(value: int) -> None:
    assert parse_value(UNS16, str(value)) == value
    assert parse_value(UNS16, hex(value)) == value
