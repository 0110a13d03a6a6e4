"""Execution mode bits of a channel (``ch<c>.mc_command_execution_mode_w``, ISG FCT-C9),
as the client names them: ``SYNCHK|MACHINE_LOCK``, or ``standard`` when no bit is set.

The service keeps the same bits in its kernel; a client never imports the service, so
the client has its own copy of the table (docs/syntax-check.md, "Execution modes").
"""

from __future__ import annotations

from enum import IntFlag

STANDARD_NAME = "standard"  # how an execution mode without any bit is shown (ISG_STANDARD)


class ExecutionMode(IntFlag):
    """Execution mode bits; 0 is ISG_STANDARD (normal machining)."""

    BLOCK_SEARCH = 0x1  # SV: block search
    SOLLKON = 0x2  # contour visualisation with output
    ON_LINE = 0x4  # online
    SYNCHK = 0x8  # syntax check
    PROD_TIME = 0x10  # machining (production) time calculation
    ONLINE_PROD_TIME = 0x20  # online production time calculation
    MACHINE_LOCK = 0x40  # dry run: no axis motion
    ADD_MDI_BLOCK = 0x80  # extended manual block mode
    KIN_TRAFO_OFF = 0x100  # kinematic transformation off
    SOLLKON_NO_OUTPUT = 0x800  # with SOLLKON: contour visualisation without output
    BEARB_MODE_SCENE = 0x1000  # machining scene mode
    SUPPRESS_TECHNO_OUTPUT = 0x2000  # no M/H/T output


def describe_execution_mode(value: int) -> str:
    """The names of the bits set in ``value``, lowest bit first, joined by ``|``
    (``SYNCHK|MACHINE_LOCK``); ``standard`` for 0; bits without a name in hex."""
    bits = value & 0xFFFFFFFF  # the object is SGN32
    if not bits:
        return STANDARD_NAME
    names = [m.name for m in ExecutionMode if bits & m]
    unknown = bits & ~sum(ExecutionMode)
    if unknown:
        names.append(f"0x{unknown:x}")
    return "|".join(names)  # type: ignore[arg-type]
