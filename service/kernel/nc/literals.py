"""Values written as NC text: the literals of the programs the decoder generates.

Built-in cycles (``cycles.positioning``) and the call-pattern wrapper (``cycle_run``)
hand NC text back to the decoder; a number in it must read back as the very float it
came from, or the generated motion would drift from the computed one.
"""

from __future__ import annotations

from decimal import Decimal


def nc_number(value: float) -> str:
    """``value`` as an NC number literal that reads back exactly (no exponent)."""
    return format(Decimal(repr(float(value))), "f")
