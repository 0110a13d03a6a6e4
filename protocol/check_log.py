"""The syntax check's log (``dec0<c>.sc`` in the output area): its file name and its line
format. The kernel writes it (``service/kernel/syntax_check``), clients parse it
(``clients.channel_ops.parse_check_log``); both take the format from here.

    ; syntax check of part.nc in channel 1
    part.nc:3: G01 X10 Y5                          (a checked line, when recorded)
    error 21220 (syntax) at part.nc:4:8: unknown word 'Q7'
    ; 12 more errors are not listed (limits.check_max_errors: the first 1000 are kept)
    ; end: 12 lines, 9 blocks, 1012 errors, complete

The end line's last field is ``complete``, ``aborted`` or ``stopped: <why>``. A file
name may hold colons: an error's position is the ``:<line>:<column>: `` after it.
"""

from __future__ import annotations

import re

#: The end line's outcome of a check that ran to the program's end.
COMPLETE = "complete"
#: The end line's outcome of a check that an error ended.
ABORTED = "aborted"
#: The prefix of the end line's outcome of a check stopped early (errors_total).
STOPPED = "stopped"

HEADER = re.compile(r"; syntax check of (.*) in channel (\d+)")
END = re.compile(r"; end: (\d+) lines, (\d+) blocks, (\d+) errors, (.*)")
ERROR = re.compile(r"error (\d+) \((\w+)\) at (.*)")
LEFT_OUT = re.compile(r"; (\d+) more errors are not listed \(.*\)")
POSITION = re.compile(r":(\d+):(\d+): ")  # after the file name of an error
CHECKED_LINE = re.compile(r":(\d+): ")  # after the file name of a checked line


def check_log_name(channel_id: int) -> str:
    """The file a syntax check in channel ``channel_id`` writes (``dec01.sc``)."""
    return f"dec0{channel_id}.sc"


def header_line(program: str, channel_id: int) -> str:
    """The first line: which program, in which channel."""
    return f"; syntax check of {program} in channel {channel_id}"


def error_line(error_id: int, category: str, file: str, line: int, column: int,
               message: str) -> str:
    """One error (``category``: syntax, semantic, ..., or ``abort`` for the one that ended
    the check)."""
    return f"error {error_id} ({category}) at {file}:{line}:{column}: {message}"


def left_out_line(count: int, why: str) -> str:
    """How many errors the log does not list, and why."""
    return f"; {count} more errors are not listed ({why})"


def end_line(lines: int, blocks: int, errors: int, outcome: str) -> str:
    """The last line: the check's counts and its outcome (``COMPLETE``, ``ABORTED``,
    ``STOPPED: ...``)."""
    return f"; end: {lines} lines, {blocks} blocks, {errors} errors, {outcome}"
