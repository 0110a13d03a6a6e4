"""ISG data types: exact sizes and little-endian codecs, as ADS carries them.

A value crosses the wire as the bytes the CNC keeps in memory: fixed size, little-endian,
strings CP1252, NUL-terminated, in a fixed-size buffer. ``encode`` refuses a value of the
wrong Python type (``TypeError``) or outside the type's range (``ValueError``);
``decode`` refuses bytes of the wrong length (``ValueError``).
"""

from __future__ import annotations

import math
import re
import struct
from dataclasses import dataclass, field
from typing import Any

STRING_ENCODING = "cp1252"


@dataclass(frozen=True, slots=True)
class DataType:
    """A fixed-size ISG type: ``name`` (ISG spelling), ``size`` in bytes, ``iec`` name."""

    name: str
    size: int
    iec: str
    kind: str  # "bool", "int", "float" or "str"
    minimum: int | float | None = None
    maximum: int | float | None = None
    _struct: struct.Struct | None = field(default=None, repr=False, compare=False)

    def encode(self, value: Any) -> bytes:
        """Encode ``value`` into exactly ``size`` little-endian bytes."""
        kind = self.kind
        if kind == "int" and type(value) is int and self.minimum <= value <= self.maximum:  # type: ignore[operator]
            return self._struct.pack(value)  # type: ignore[union-attr]  # the common case
        match kind:
            case "bool":
                if not isinstance(value, int):
                    raise TypeError(f"{self.name} takes true/false or 0/1, not {value!r}")
                if value not in (0, 1):
                    raise ValueError(f"{self.name} takes true/false or 0/1, not {value!r}")
                return b"\x01" if value else b"\x00"
            case "int":
                if isinstance(value, bool) or not isinstance(value, int):
                    raise TypeError(f"{self.name} takes an integer, not {value!r}")
                if not self.minimum <= value <= self.maximum:  # type: ignore[operator]
                    raise ValueError(
                        f"{value} is outside {self.name} [{self.minimum}, {self.maximum}]"
                    )
                return self._struct.pack(value)  # type: ignore[union-attr]
            case "float":
                if isinstance(value, bool) or not isinstance(value, (int, float)):
                    raise TypeError(f"{self.name} takes a number, not {value!r}")
                try:
                    number = float(value)
                    if self.size == 4 and math.isfinite(number) and abs(number) > self.maximum:  # type: ignore[operator]
                        raise OverflowError
                    return self._struct.pack(number)  # type: ignore[union-attr]
                except (OverflowError, struct.error):
                    raise ValueError(f"{value} is outside the range of {self.name}") from None
            case _:
                return self._encode_string(value)

    def decode(self, data: bytes) -> Any:
        """Decode exactly ``size`` bytes into a Python value."""
        if len(data) != self.size:
            raise ValueError(f"{self.name} needs {self.size} bytes, got {len(data)}")
        match self.kind:
            case "bool":
                return data != b"\x00"
            case "str":
                end = data.find(b"\x00")
                return data[: end if end >= 0 else len(data)].decode(STRING_ENCODING)
            case _:
                return self._struct.unpack(data)[0]  # type: ignore[union-attr]

    def encode_fitted(self, text: str) -> bytes:
        """A STRING value the CNC produced, made to fit (``fit_string``) and encoded: what
        a read of a kernel text answers, where ``encode`` would refuse it."""
        return _fitted(text, self.size).ljust(self.size, b"\x00")

    def _encode_string(self, value: Any) -> bytes:
        if not isinstance(value, str):
            raise TypeError(f"{self.name} takes a string, not {value!r}")
        try:
            raw = value.encode(STRING_ENCODING)
        except UnicodeEncodeError as exc:
            raise ValueError(f"{value!r} has characters CP1252 cannot encode") from exc
        if b"\x00" in raw:
            raise ValueError("a string value cannot contain NUL")
        if len(raw) > self.size - 1:
            raise ValueError(
                f"{len(raw)} characters do not fit {self.name} (at most {self.size - 1})"
            )
        return raw.ljust(self.size, b"\x00")


ELLIPSIS = "\u2026"  # CP1252 0x85: marks a text cut to fit its buffer


def fit_string(text: str, size: int) -> str:
    """``text`` made to fit a STRING(``size``) buffer, for values the CNC itself produces
    (error and message texts, names): a NUL or a character CP1252 lacks becomes "?", and
    a text longer than ``size - 1`` bytes is cut and ends in an ellipsis. ``encode`` still
    refuses such values from a client; this is for showing what the kernel has to say."""
    return _fitted(text, size).decode(STRING_ENCODING)


def _fitted(text: str, size: int) -> bytes:
    """The CP1252 bytes of ``fit_string`` (without the NUL padding)."""
    fitted = text.encode(STRING_ENCODING, errors="replace").replace(b"\x00", b"?")
    if len(fitted) > size - 1:
        fitted = fitted[: max(size - 2, 0)] + ELLIPSIS.encode(STRING_ENCODING)
        fitted = fitted[: size - 1]
    return fitted


def _integer(name: str, size: int, signed: bool, iec: str) -> DataType:
    fmt = {1: "b", 2: "h", 4: "i", 8: "q"}[size]
    fmt = fmt if signed else fmt.upper()
    bits = size * 8
    lo, hi = (-(1 << (bits - 1)), (1 << (bits - 1)) - 1) if signed else (0, (1 << bits) - 1)
    return DataType(name, size, iec, "int", lo, hi, struct.Struct("<" + fmt))


BOOLEAN = DataType("BOOLEAN", 1, "BOOL", "bool", 0, 1)
UNS08 = _integer("UNS08", 1, False, "USINT")
SGN08 = _integer("SGN08", 1, True, "SINT")
UNS16 = _integer("UNS16", 2, False, "UINT")
SGN16 = _integer("SGN16", 2, True, "INT")
UNS32 = _integer("UNS32", 4, False, "UDINT")
SGN32 = _integer("SGN32", 4, True, "DINT")
UNS64 = _integer("UNS64", 8, False, "ULINT")
SGN64 = _integer("SGN64", 8, True, "LINT")
REAL32 = DataType("REAL32", 4, "REAL", "float", None, 3.4028234663852886e38, struct.Struct("<f"))
REAL64 = DataType("REAL64", 8, "LREAL", "float", None, None, struct.Struct("<d"))

SCALAR_TYPES: dict[str, DataType] = {
    t.name: t
    for t in (BOOLEAN, UNS08, SGN08, UNS16, SGN16, UNS32, SGN32, UNS64, SGN64, REAL32, REAL64)
}

_STRING_RE = re.compile(r"^STRING\((\d+)\)$")
_STRING_CACHE: dict[int, DataType] = {}


def STRING(size: int) -> DataType:
    """A fixed string buffer of ``size`` bytes including the NUL terminator."""
    if size < 1 or size > 65536:
        raise ValueError(f"STRING size must be 1..65536 bytes, not {size}")
    cached = _STRING_CACHE.get(size)
    if cached is None:
        cached = _STRING_CACHE[size] = DataType(f"STRING({size})", size, "STRING", "str")
    return cached


def parse_type(name: str) -> DataType:
    """Return the type named ``name`` (``UNS16``, ``REAL64``, ``STRING(84)``; any case)."""
    text = name.strip().upper()
    if text in SCALAR_TYPES:
        return SCALAR_TYPES[text]
    match = _STRING_RE.match(text)
    if match:
        return STRING(int(match.group(1)))
    known = ", ".join([*SCALAR_TYPES, "STRING(n)"])
    raise ValueError(f"unknown data type {name!r}; known: {known}")


def parse_value(dtype: DataType, text: str) -> Any:
    """Parse a value typed by a person (CLI, MQTT) for ``dtype``.

    Integers in decimal or hex (``0x1f``), booleans as exactly 0/1/true/false (any case;
    the message of a refusal lists these and nothing else is taken), reals as floats,
    strings as given. Raises ``ValueError`` with a readable message.
    """
    match dtype.kind:
        case "bool":
            lowered = text.strip().lower()
            if lowered in ("1", "true"):
                return True
            if lowered in ("0", "false"):
                return False
            raise ValueError(f"{text!r} is not a boolean (0/1/true/false)")
        case "int":
            stripped = text.strip()
            try:
                return int(stripped, 0)
            except ValueError:
                pass
            try:  # int(x, 0) refuses decimals with leading zeros ("007")
                return int(stripped, 10)
            except ValueError:
                raise ValueError(f"{text!r} is not an integer for {dtype.name}") from None
        case "float":
            try:
                return float(text.strip())
            except ValueError:
                raise ValueError(f"{text!r} is not a number for {dtype.name}") from None
        case _:
            return text
