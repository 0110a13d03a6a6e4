"""Call frames of the decoder: one per running (sub)program."""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import IntEnum
from typing import Any

from .blocks import MotionKind
from .modal import DistanceMode, Plane
from .program import Program, Section
from .statements import Control, StmtKind
from .variables import Value, Variable

MAX_CALL_DEPTH = 20  # subprogram nesting below the main program


class CallFrameKind(IntEnum):
    """What kind of program a frame runs."""

    MAIN = 0  # the main program (or the manual block)
    LOCAL = 1  # a %L subprogram, called with LL
    FILE = 2  # a file subprogram, called with L


@dataclass(slots=True)
class ControlEntry:
    """An open control block of a frame ($IF being executed, loop, $SWITCH)."""

    kind: StmtKind  # IF, WHILE, FOR, REPEAT, SWITCH or RT_WHILE
    index: int  # line index of the opening statement
    stmt: Control
    body: int  # line index of the first line of the body
    end: float = 0.0  # $FOR: end value
    step: float = 1.0  # $FOR: step


@dataclass(slots=True)
class CallFrame:
    """A running (sub)program: where it is, its variables and open control blocks."""

    program: Program
    section: Section
    index: int  # next line to decode
    kind: CallFrameKind
    local_vars: dict[str, Variable] = field(default_factory=dict)  # V.L.
    cycle_vars: dict[str, Variable] = field(default_factory=dict)  # V.CYC. declared here
    control: list[ControlEntry] = field(default_factory=list)
    jumped: bool = False  # a $GOTO ran in this frame (it may enter $IF blocks from outside)
    # a cycle: its @P parameters (None: no cycle), the caller's modal G functions to
    # restore when it returns, and for the pattern wrapper the call it repeats
    cycle_params: dict[int, Value] | None = None
    restore: tuple[MotionKind, DistanceMode, Plane] | None = None
    # the pattern wrapper: the cycle call it repeats (a cycle_run.CycleCall; cycle_run
    # imports this module, so the type is not named here)
    pattern_call: Any = None
