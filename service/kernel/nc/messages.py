"""``#MSG`` texts: a printf format with arguments, as ISG programs write them.

``#MSG SAVE ["Center X = %f", V.CYC.SysRetCenterX]`` formats like C's printf: ``%f``,
``%e``, ``%g``, ``%d``/``%i`` (integer part), ``%x``, ``%s`` and ``%%``, with flags,
width and precision (each at most 99, so a format cannot ask for gigabytes).
"""

from __future__ import annotations

import math
import re

from .errors import NcErrorId
from .variables import Value, VariableFault

_SPEC = re.compile(r"%([-+ #0]*)([0-9]*)(?:\.([0-9]*))?([a-zA-Z%])")
_CONVERSIONS = frozenset("fFeEgGdixXs%")
MAX_WIDTH = 99


def format_message(fmt: str, args: tuple[Value, ...]) -> str:
    """``fmt`` with ``args`` filled in; VariableFault (MESSAGE_FORMAT) when they do not fit."""
    out: list[str] = []
    k = 0
    last = 0
    for m in _SPEC.finditer(fmt):
        out.append(fmt[last:m.start()])
        last = m.end()
        flags, width, precision, conv = m.groups()
        if conv == "%":
            out.append("%")
            continue
        if conv not in _CONVERSIONS:
            raise VariableFault(NcErrorId.MESSAGE_FORMAT, f"unknown conversion %{conv} in #MSG")
        if (width and int(width) > MAX_WIDTH) or (precision and int(precision) > MAX_WIDTH):
            raise VariableFault(NcErrorId.MESSAGE_FORMAT,
                                f"width and precision in #MSG are at most {MAX_WIDTH}")
        if k >= len(args):
            raise VariableFault(NcErrorId.MESSAGE_FORMAT,
                                f"#MSG format needs more than the {len(args)} value(s) given")
        value = args[k]
        k += 1
        out.append(_convert(m.group(), conv, value))
    out.append(fmt[last:])
    if k < len(args):
        raise VariableFault(NcErrorId.MESSAGE_FORMAT,
                            f"#MSG got {len(args)} value(s) but its format uses {k}")
    return "".join(out)


def _convert(spec: str, conv: str, value: Value) -> str:
    if conv == "s":
        text = value if isinstance(value, str) else f"{value:g}" if isinstance(value, float) \
            else str(value)
        return spec % text
    if isinstance(value, str):
        raise VariableFault(NcErrorId.MESSAGE_FORMAT, f"{spec} needs a number, got a string")
    number = float(value)
    if conv in "dixX":
        if not math.isfinite(number):
            raise VariableFault(NcErrorId.MESSAGE_FORMAT, f"{spec}: {number} is no integer")
        return spec.replace("i", "d") % int(number)
    return spec % number
