"""Execution mode bits of a channel (``ch<c>.mc_command_execution_mode_w``, ISG FCT-C9),
as the client names them: ``SYNCHK|MACHINE_LOCK``, or ``standard`` when no bit is set.

The bits are ``protocol.values.ExecutionMode``, shared with the kernel
(docs/syntax-check.md, "Execution modes").
"""

from __future__ import annotations

from cnc_objects.protocol.values import ExecutionMode

STANDARD_NAME = "standard"  # how an execution mode without any bit is shown (ISG_STANDARD)


def describe_execution_mode(value: int) -> str:
    """The names of the bits set in ``value``, lowest bit first, joined by ``|``
    (``SYNCHK|MACHINE_LOCK``); ``standard`` for 0; bits without a name in hex."""
    bits = value & 0xFFFFFFFF  # the object is SGN32
    if not bits:
        return STANDARD_NAME
    names = [m.name for m in ExecutionMode if m and bits & m]
    unknown = bits & ~sum(ExecutionMode)
    if unknown:
        names.append(f"0x{unknown:x}")
    return "|".join(names)  # type: ignore[arg-type]
