"""NC variables: scopes, types, scalars and arrays.

Scopes (``V.<scope>.<name>``):

* ``V.L.`` local to the (sub)program whose ``#VAR`` block declared it; a subprogram
  call starts with no V.L. variables.
* ``V.P.`` program-global: declared in the main program (a ``#VAR`` block of a
  subprogram may not declare them), visible in every subprogram. They live in the
  ``ModalState``, so an extended manual block sees the ones of the block before.
* ``V.G.`` global: live in the ``ModalState`` and survive every decoder. They may be
  pre-set by the caller or declared in any ``#VAR`` block; declaring one that exists
  already keeps its value (a global is created once).
* ``V.CYC.`` cycle variables: declared in any ``#VAR`` block, visible in the declaring
  (sub)program and in everything it calls (a cycle writes results into the V.CYC.
  variables its caller declared); they end with the declaring program.

Names are case-insensitive (stored upper case). Values are ``float`` for REAL types,
``int`` for integer types, ``bool`` for BOOLEAN and ``str`` for STRING. Assigning a
real to an integer variable rounds to the nearest integer (half away from zero).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import IntEnum

from .errors import NcErrorId


class Scope(IntEnum):
    """Where a variable lives (the part after ``V.``)."""

    L = 0  # V.L.: local to the declaring (sub)program
    P = 1  # V.P.: program-global (main program and all subprograms)
    G = 2  # V.G.: global, survives between decoders
    CYC = 3  # V.CYC.: cycle variables, visible in called subprograms


class VarType(IntEnum):
    """Data type of a variable (``: TYPE`` in ``#VAR``; REAL64 when omitted)."""

    BOOLEAN = 0  # TRUE/FALSE; any non-zero number is TRUE
    UNS08 = 1  # 0 .. 255
    SGN08 = 2  # -128 .. 127
    UNS16 = 3  # 0 .. 65535
    SGN16 = 4  # -32768 .. 32767
    UNS32 = 5  # 0 .. 2**32-1
    SGN32 = 6  # -2**31 .. 2**31-1
    REAL32 = 7  # floating point (kept as a Python float)
    REAL64 = 8  # floating point, the default
    STRING = 9  # text


# integer types: (minimum, maximum)
_INT_RANGE = {
    VarType.UNS08: (0, 0xFF),
    VarType.SGN08: (-0x80, 0x7F),
    VarType.UNS16: (0, 0xFFFF),
    VarType.SGN16: (-0x8000, 0x7FFF),
    VarType.UNS32: (0, 0xFFFFFFFF),
    VarType.SGN32: (-0x80000000, 0x7FFFFFFF),
}

_DEFAULT: dict[VarType, Value] = {
    VarType.BOOLEAN: False, VarType.REAL32: 0.0, VarType.REAL64: 0.0, VarType.STRING: "",
}

Value = float | int | bool | str


class VariableFault(Exception):
    """A value problem without a place; the caller turns it into an NcError."""

    def __init__(self, err_id: NcErrorId, message: str) -> None:
        super().__init__(message)
        self.err_id = err_id
        self.message = message


def round_half_away(x: float) -> int:
    """Round to the nearest integer, halves away from zero (2.5 -> 3, -2.5 -> -3)."""
    return int(math.floor(abs(x) + 0.5)) * (1 if x >= 0 else -1)


def convert(vtype: VarType, value: Value, name: str) -> Value:
    """``value`` converted for a variable of type ``vtype``; VariableFault when impossible."""
    if vtype == VarType.STRING:
        if not isinstance(value, str):
            raise VariableFault(NcErrorId.TYPE_MISMATCH, f"{name} is a STRING, not a number")
        return value
    if isinstance(value, str):
        raise VariableFault(NcErrorId.TYPE_MISMATCH, f"{name} is a number, not a STRING")
    if vtype == VarType.BOOLEAN:
        return value != 0
    if vtype in (VarType.REAL64, VarType.REAL32):
        return float(value)
    if not math.isfinite(value):
        raise VariableFault(NcErrorId.VALUE_OUT_OF_TYPE_RANGE, f"{value} does not fit {name}")
    number = round_half_away(float(value)) if not isinstance(value, int) else int(value)
    low, high = _INT_RANGE[vtype]
    if not low <= number <= high:
        raise VariableFault(
            NcErrorId.VALUE_OUT_OF_TYPE_RANGE,
            f"{number} is outside the range of {name} ({vtype.name}: {low} .. {high})",
        )
    return number


def default_value(vtype: VarType) -> Value:
    """The value of a declared variable without initializer."""
    return _DEFAULT.get(vtype, 0)


@dataclass(slots=True)
class Variable:
    """A declared variable: a scalar (``dims`` empty) or an array (``values`` flat)."""

    name: str  # full name for messages, e.g. "V.L.COUNT"
    vtype: VarType
    dims: tuple[int, ...]
    values: list[Value]  # one value for a scalar; row-major elements for an array
    site: tuple[str, int] = ("", -1)  # (file, physical index) of the declaration

    def _flat(self, indices: tuple[int, ...]) -> int:
        if len(indices) != len(self.dims):
            if not self.dims:
                raise VariableFault(NcErrorId.ARRAY_INDEX_MISMATCH, f"{self.name} is not an array")
            raise VariableFault(
                NcErrorId.ARRAY_INDEX_MISMATCH,
                f"{self.name} needs {len(self.dims)} index(es), got {len(indices)}",
            )
        flat = 0
        for index, size in zip(indices, self.dims, strict=True):
            if not 0 <= index < size:
                raise VariableFault(
                    NcErrorId.ARRAY_INDEX_OUT_OF_RANGE,
                    f"index {index} of {self.name} is outside 0..{size - 1}",
                )
            flat = flat * size + index
        return flat

    def get(self, indices: tuple[int, ...] = ()) -> Value:
        """The value (of one element of an array)."""
        if not indices and not self.dims:
            return self.values[0]
        return self.values[self._flat(indices)]

    def set(self, value: Value, indices: tuple[int, ...] = ()) -> None:
        """Assign with conversion to the variable's type."""
        flat = 0 if not indices and not self.dims else self._flat(indices)
        self.values[flat] = convert(self.vtype, value, self.name)
