"""What one logical line means once parsed: an NC block, a control statement, ...

Statements are parsed once per line and cached by the program, so a loop body is not
parsed again on every pass. Values are either floats (constants) or expression nodes
evaluated when the statement runs.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import IntEnum
from typing import TypeAlias, final

from .blocks import AxisExchangeKind, ContourKind
from .expressions import Node, VarRef
from .source import LogicalLine
from .variables import Scope, VarType

#: an initializer list of ``#VAR``: expressions, nested lists for the rows of an array
InitList: TypeAlias = list["Node | InitList"]


class StmtKind(IntEnum):
    """Kind of a parsed line."""

    BLOCK = 0  # an NC block: words, assignments, calls, $GOTO
    IF = 1  # $IF cond
    IF_GOTO = 2  # $IF cond $GOTO target (one line, no $ENDIF)
    ELSEIF = 3  # $ELSEIF cond
    ELSE = 4  # $ELSE
    ENDIF = 5  # $ENDIF
    WHILE = 6  # $WHILE cond
    ENDWHILE = 7  # $ENDWHILE
    FOR = 8  # $FOR var = start, end [, step]
    ENDFOR = 9  # $ENDFOR
    REPEAT = 10  # $REPEAT
    UNTIL = 11  # $UNTIL cond
    SWITCH = 12  # $SWITCH expr
    CASE = 13  # $CASE value [, value ...]
    DEFAULT = 14  # $DEFAULT
    BREAK = 15  # $BREAK: leave the innermost $SWITCH or loop
    CONTINUE = 16  # $CONTINUE: next pass of the innermost loop
    ENDSWITCH = 17  # $ENDSWITCH
    VAR = 18  # #VAR: declarations follow up to #ENDVAR
    ENDVAR = 19  # #ENDVAR (only legal as the end of a #VAR block)
    RT_WHILE = 20  # #RT WHILE [cond]: real-time loop, unrolled at decode time
    RT_ENDWHILE = 21  # #RT ENDWHILE


# closing statement -> the opening statement it belongs to
CLOSER_OF = {
    StmtKind.ENDIF: StmtKind.IF,
    StmtKind.ENDWHILE: StmtKind.WHILE,
    StmtKind.ENDFOR: StmtKind.FOR,
    StmtKind.UNTIL: StmtKind.REPEAT,
    StmtKind.ENDSWITCH: StmtKind.SWITCH,
    StmtKind.RT_ENDWHILE: StmtKind.RT_WHILE,
}
OPENERS = frozenset(CLOSER_OF.values())
LOOPS = frozenset({StmtKind.WHILE, StmtKind.FOR, StmtKind.REPEAT, StmtKind.RT_WHILE})

# how a statement kind is written, for messages
SPELLING = {
    StmtKind.IF: "$IF", StmtKind.IF_GOTO: "$IF", StmtKind.ELSEIF: "$ELSEIF",
    StmtKind.ELSE: "$ELSE", StmtKind.ENDIF: "$ENDIF", StmtKind.WHILE: "$WHILE",
    StmtKind.ENDWHILE: "$ENDWHILE", StmtKind.FOR: "$FOR", StmtKind.ENDFOR: "$ENDFOR",
    StmtKind.REPEAT: "$REPEAT", StmtKind.UNTIL: "$UNTIL", StmtKind.SWITCH: "$SWITCH",
    StmtKind.CASE: "$CASE", StmtKind.DEFAULT: "$DEFAULT", StmtKind.BREAK: "$BREAK",
    StmtKind.CONTINUE: "$CONTINUE", StmtKind.ENDSWITCH: "$ENDSWITCH", StmtKind.VAR: "#VAR",
    StmtKind.ENDVAR: "#ENDVAR", StmtKind.RT_WHILE: "#RT WHILE",
    StmtKind.RT_ENDWHILE: "#RT ENDWHILE",
}


class WordKind(IntEnum):
    """Meaning of an address letter in an NC block."""

    AXIS = 0  # a channel axis (or X in a G4 block: the dwell time)
    OFFSET = 1  # I/J/K: centre offset for the axis named X/Y/Z
    RADIUS = 2  # R: arc radius
    FEED = 3  # F: feed in mm/min (in a G4 block: the dwell time)
    SPINDLE = 4  # S: spindle speed in rpm
    TOOL = 5  # T: tool number
    TOOL_OFFSET = 6  # D: tool radius entry
    G = 7  # G: preparatory function
    M = 8  # M: miscellaneous function
    WEIGHTING = 9  # G133 = <%> / G134 = <%>: acceleration / ramp time weighting
    LOOK_AHEAD = 10  # LA_ON (value 1) / LA_OFF (value 0): enhanced look-ahead
    LOOK_AHEAD_PARAM = 11  # METB = <s> / VFBT = <factor> / BBTRC = <blocks>
    ZERO_OFFSET_INDEX = 12  # G159 = <i>: zero offset group np_grp[i]
    H = 13  # H: technology function to the PLC (ISG's H functions)
    SPINDLE_POS = 14  # S.POS = <degrees>: the position M19 orients the spindle to
    SPINDLE_REV = 15  # REV<rpm> in S[...]: the speed (S), negative is ISG's 20991


@final  # the decoder dispatches on type(stmt) is ...: no subclasses
@dataclass(slots=True)
class Word:
    """An address letter with its value (float constant or expression node)."""

    kind: WordKind
    letter: str
    value: float | Node
    pos: int  # position of the letter in the logical line
    axis: int = -1  # AXIS: channel axis index (-1: X without such an axis); OFFSET: too


@final
@dataclass(slots=True)
class Assign:
    """``V.x.y = expr`` inside an NC block."""

    target: VarRef
    value: Node
    pos: int


@dataclass(slots=True)
class CycleParam:
    """``@P<n> = <expr>`` of a cycle call."""

    number: int
    value: Node
    pos: int  # position of the '@'


@dataclass(slots=True)
class CycleArgs:
    """What ``L CYCLE [NAME=.. @P1=.. PATTERN_ID=.. PATTERN_RETRACT=..]`` passes."""

    params: tuple[CycleParam, ...]
    pattern_id: Node | None = None
    pattern_id_pos: int = -1
    pattern_retract: Node | None = None
    pattern_retract_pos: int = -1


@dataclass(slots=True)
class Call:
    """``LL name`` (local) or ``L name`` (file subprogram); with ``cycle`` a cycle call
    ``L CYCLE [NAME=name ...]`` (``LL CYCLE``: a ``%L`` section as the cycle), ``pos``
    then points at ``NAME``'s value."""

    local: bool
    name: str
    pos: int
    cycle: CycleArgs | None = None


@dataclass(slots=True)
class Goto:
    """``$GOTO Nnn`` / ``$GOTO [NAME]``; ``label`` is normalised ("N10", "[NAME]")."""

    label: str
    pos: int


@final
@dataclass(slots=True)
class NcBlock:
    """An NC block: its items in program order, evaluated left to right."""

    line: LogicalLine
    number: int | None = None
    items: list[Word | Assign] = field(default_factory=list)
    call: Call | None = None
    goto: Goto | None = None
    letters: frozenset[str] = frozenset()  # the address letters present (besides G and M)
    has_g4: bool = False  # a constant G4 (dwell) is in the block


@final
@dataclass(slots=True)
class Control:
    """A control statement ($IF ... $ENDSWITCH, #VAR, #RT WHILE, ...)."""

    kind: StmtKind
    line: LogicalLine
    pos: int  # position of the keyword
    expr: Node | None = None  # condition / switch value / $FOR start
    goto: Goto | None = None  # IF_GOTO
    target: VarRef | None = None  # $FOR loop variable
    end: Node | None = None  # $FOR end value
    step: Node | None = None  # $FOR step (None: 1)
    values: tuple[Node, ...] = ()  # $CASE values
    number: int | None = None  # N number of the line, if any


@dataclass(slots=True)
class AxisRef:
    """One axis of an ``#AX`` command: ``X`` (RELEASE), ``2`` (RELEASE NBR) or
    ``X, 1, 0`` (REQUEST: name, logical axis number, channel axis index)."""

    pos: int  # position of the first part
    name: str | None = None  # upper case
    number: Node | None = None  # logical axis number
    number_pos: int = -1
    index: Node | None = None  # axis index in the channel (from 0)
    index_pos: int = -1


@final
@dataclass(slots=True)
class AxisCommand:
    """``#AX RELEASE`` / ``#AX REQUEST``: alone in its NC line (besides N and a label)."""

    kind: AxisExchangeKind
    line: LogicalLine
    pos: int  # position of the '#'
    axes: tuple[AxisRef, ...] | None  # None: #AX RELEASE ALL
    number: int | None = None  # N number of the line, if any


@final
@dataclass(slots=True)
class ContourStatement:
    """``#CONTOUR LOOKAHEAD LOG ...`` or ``#DISTANCE PROG START CLEAR``: alone in its NC
    line (besides N and a label)."""

    kind: ContourKind  # LOG_ON, LOG_PARAM, LOG_OFF, LOG_CLEAR or DISTANCE_CLEAR
    line: LogicalLine
    pos: int  # position of the '#'
    param: Node | None = None  # PARAM= expression (evaluated when the command runs)
    param_pos: int = -1  # position of the PARAM expression
    number: int | None = None  # N number of the line, if any


@dataclass(slots=True)
class Declaration:
    """One variable in a ``#VAR`` block."""

    scope: Scope
    name: str
    vtype: VarType
    dims: tuple[int, ...]
    init: Node | InitList | None  # expression, or nested lists of expressions for arrays
    line: LogicalLine
    pos: int
