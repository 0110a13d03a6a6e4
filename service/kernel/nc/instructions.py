"""The ``#`` instructions of cycles and their surroundings: parsing.

Each stands alone in its NC line (an N number and a label may precede it):

* ``#CS ON [x, y, z, a, b, c]``, ``#CS ON [name] [..]``, ``#CS DEF [name] [..]``,
  ``#CS ON [name]``, ``#CS ADD [name] [..]``, ``#CS OFF``, ``#CS OFF ALL``: machining
  coordinate systems (``coordinates``); three values are an offset only.
* ``#PATTERN BEGIN [ID=<expr>]``, ``#AT [x, y, z]`` / ``#AT [x, y, z, a, b, c]``,
  ``#PATTERN END``, ``#PATTERN DELETE [ID=<expr>]``, ``#PATTERN DELETE ALL``: call
  patterns (``ID<expr>`` without ``=`` is accepted too, as ISG writes it).
* ``#FILE NAME [MSG="<file>"]``: the file ``#MSG SAVE`` writes to.
* ``#MSG ["<format>", args]``: a message for the channel's message list;
  ``#MSG SAVE [EXCLUSIVE] ["<format>", args]``: a line for the file (``messages``).
* ``#TRAFO ON`` / ``#TRAFO OFF``: kinematic transformation (``technology``).
* ``#HSC ON [SURFACE PATH_DEV=.. TRACK_DEV=..]`` / ``#HSC OFF``, ``#SLOPE [TYPE=..]``,
  ``#FILTER ON [AX_DEV=..]`` / ``#FILTER OFF``: high-speed settings (``technology``).

Values are expressions, evaluated when the instruction runs (``instruction_run``).
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass, field
from enum import IntEnum
from typing import final

from .errors import NcErrorId
from .expressions import ExpressionParser, Node
from .lexer import IDENT, Cursor
from .source import LogicalLine

WORDS = frozenset({"CS", "PATTERN", "AT", "FILE", "MSG", "TRAFO", "HSC", "SLOPE", "FILTER",
                   "ORI"})
_KEY = re.compile(r"[A-Z_][A-Z0-9_]*")
_CS_NAME = re.compile(r"\[[ \t]*([A-Z_][A-Z0-9_]*)[ \t]*\]")
SLOPE_TYPES = ("STEP", "TRAPEZ", "HSC")
HSC_OPTIONS = {"SURFACE": False, "PATH_DEV": True, "TRACK_DEV": True}  # key -> takes a value
FILTER_OPTIONS = {"AX_DEV": True}


class InstructionKind(IntEnum):
    """What an instruction does."""

    CS_ON = 1  # select a coordinate system (values, a defined name, or both: define+select)
    CS_DEF = 2  # define a named coordinate system
    CS_OFF = 3  # deselect the last (``all``: every) coordinate system
    PATTERN_BEGIN = 10
    PATTERN_END = 11
    PATTERN_DELETE = 12  # ``all`` or ``values[0]`` the id
    PATTERN_CALL = 14  # the cycle call of the pattern wrapper (cycle_run) at this position
    AT = 13  # one position of the pattern being defined
    FILE_NAME = 20  # #FILE NAME [MSG="..."]
    MSG = 21  # #MSG ["fmt", args]: to the message list
    MSG_SAVE = 22  # #MSG SAVE [EXCLUSIVE] ["fmt", args]: to the file
    TRAFO = 30  # #TRAFO ON/OFF (``on``)
    HSC = 31  # #HSC ON [..] / OFF
    SLOPE = 32  # #SLOPE [TYPE=..]
    FILTER = 33  # #FILTER ON [..] / OFF
    ORI_MODE = 34  # #ORI MODE [VECTOR_2DOF] / [ANGLE] (``name``)


@final  # the decoder dispatches on type(stmt) is Instruction: no subclasses
@dataclass(slots=True)
class Instruction:
    """One parsed ``#`` instruction of this module."""

    kind: InstructionKind
    line: LogicalLine
    pos: int  # position of the '#'
    number: int | None = None  # N number of the line
    values: tuple[Node, ...] = ()  # the bracket list: #CS values, #AT values, #MSG args
    value_pos: tuple[int, ...] = ()
    name: str = ""  # #CS name, #FILE file name, #SLOPE type
    on: bool = True  # #TRAFO/#HSC/#FILTER ON, #CS OFF ALL -> all
    all: bool = False  # #CS OFF ALL, #PATTERN DELETE ALL
    exclusive: bool = False  # #MSG SAVE EXCLUSIVE
    text: Node | None = None  # #MSG format
    text_pos: int = -1
    options: dict[str, tuple[Node | None, int]] = field(default_factory=dict)


def parse_instruction(cur: Cursor, word: str, hash_pos: int, number: int | None) -> Instruction:
    """The instruction ``#<word>`` whose ``#`` is at ``hash_pos``; the cursor stands
    after the word."""
    stmt = Instruction(InstructionKind.MSG, cur.line, hash_pos, number)
    parse = _PARSERS[word]
    parse(cur, stmt)
    if not cur.at_end():
        raise cur.error(_syntax_id(word),
                        f"unexpected '{cur.word_text()}' after #{word}: it stands alone "
                        "in its NC line")
    return stmt


# ---------------------------------------------------------------- pieces

def _syntax_id(word: str) -> NcErrorId:
    """The id of a malformed ``#<word>``: #PATTERN and #AT have their own (errors.py)."""
    return NcErrorId.PATTERN_SYNTAX if word in ("PATTERN", "AT") else NcErrorId.INSTRUCTION_SYNTAX


def _sub(cur: Cursor, word: str, allowed: tuple[str, ...], optional: bool = False) -> str:
    cur.skip_ws()
    pos = cur.pos
    m = cur.match(IDENT)
    sub = m.group() if m is not None else ""
    if sub in allowed:
        return sub
    if optional and not sub:
        return ""
    cur.pos = pos
    shown = f"'{cur.word_text()}'" if not cur.at_end() else "the end of the line"
    raise cur.error(_syntax_id(word),
                    f"#{word} needs {' or '.join(allowed)}, found {shown}", pos)


def _open(cur: Cursor, expected: str, err_id: NcErrorId = NcErrorId.INSTRUCTION_SYNTAX
          ) -> int:
    """Past the '[' that opens an instruction's list (blanks before it skipped); its
    position. ``err_id`` with ``expected`` (what should follow) when there is none."""
    cur.skip_ws()
    open_pos = cur.pos
    if cur.peek() != "[":
        raise cur.error(err_id, expected)
    cur.pos += 1
    return open_pos


def _list(cur: Cursor, what: str, counts: tuple[int, ...],
          err_id: NcErrorId = NcErrorId.INSTRUCTION_SYNTAX,
          ) -> tuple[tuple[Node, ...], tuple[int, ...]]:
    """``[expr, expr, ...]`` with one of ``counts`` elements."""
    open_pos = _open(cur, f"'[' expected after {what}", err_id)
    parser = ExpressionParser(cur)
    values: list[Node] = []
    positions: list[int] = []
    while True:
        cur.skip_ws()
        positions.append(cur.pos)
        values.append(parser.parse())
        cur.skip_ws()
        if cur.peek() == ",":
            cur.pos += 1
            continue
        parser.expect("]", open_pos)
        break
    if len(values) not in counts:
        wanted = " or ".join(str(c) for c in counts)
        raise cur.error(err_id, f"{what} takes {wanted} values, got {len(values)}", open_pos)
    return tuple(values), tuple(positions)


def _options(cur: Cursor, what: str, known: dict[str, bool]) -> dict[str, tuple[Node | None, int]]:
    """``[KEY KEY=expr ...]`` (optional; blanks or commas between the entries)."""
    cur.skip_ws()
    if cur.peek() != "[":
        return {}
    open_pos = cur.pos
    cur.pos += 1
    parser = ExpressionParser(cur)
    found: dict[str, tuple[Node | None, int]] = {}
    while True:
        cur.skip_ws()
        if cur.peek() == ",":
            cur.pos += 1
            continue
        if cur.peek() == "]":
            cur.pos += 1
            return found
        if cur.pos >= cur.end:
            parser.expect("]", open_pos)
        pos = cur.pos
        m = cur.match(_KEY)
        key = m.group() if m is not None else ""
        if key not in known:
            cur.pos = pos
            raise cur.error(NcErrorId.INSTRUCTION_SYNTAX,
                            f"unknown option '{cur.word_text()}' of {what} (this kernel "
                            f"knows {', '.join(known)})", pos)
        if key in found:
            raise cur.error(NcErrorId.INSTRUCTION_SYNTAX, f"{key} given twice in {what}", pos)
        value = None
        if known[key]:
            cur.skip_ws()
            if cur.peek() != "=":
                raise cur.error(NcErrorId.INSTRUCTION_SYNTAX, f"'=' expected after {key}")
            cur.pos += 1
            value = parser.parse()
        found[key] = (value, pos)


def _id(cur: Cursor, what: str) -> tuple[Node, int]:
    """``[ID=<expr>]`` or ``[ID<expr>]``."""
    open_pos = _open(cur, f"'[ID=<number>]' expected after {what}", NcErrorId.PATTERN_SYNTAX)
    cur.skip_ws()
    if not cur.startswith("ID"):
        raise cur.error(NcErrorId.PATTERN_SYNTAX, f"ID expected in {what} [ID=<number>]")
    cur.pos += 2
    cur.skip_ws()
    if cur.peek() == "=":
        cur.pos += 1
    cur.skip_ws()
    pos = cur.pos
    parser = ExpressionParser(cur)
    value = parser.parse()
    parser.expect("]", open_pos)
    return value, pos


# ---------------------------------------------------------------- the instructions

def _cs(cur: Cursor, stmt: Instruction) -> None:
    sub = _sub(cur, "CS", ("ON", "OFF", "DEF", "ADD"))
    if sub == "OFF":
        stmt.kind = InstructionKind.CS_OFF
        cur.skip_ws()
        if cur.startswith("ALL"):
            cur.pos += 3
            stmt.all = True
        return
    stmt.kind = InstructionKind.CS_DEF if sub == "DEF" else InstructionKind.CS_ON
    cur.skip_ws()
    m = cur.match(_CS_NAME)
    if m is not None:
        stmt.name = m.group(1)
    cur.skip_ws()
    if cur.peek() == "[":
        stmt.values, stmt.value_pos = _list(cur, f"#CS {sub}", (3, 6))
    elif sub != "ON" or not stmt.name:
        raise cur.error(NcErrorId.INSTRUCTION_SYNTAX,
                        f"#CS {sub} needs [x, y, z, a, b, c]"
                        + ("" if sub == "ON" else " after its name"))
    if sub == "DEF" and not stmt.name:
        raise cur.error(NcErrorId.INSTRUCTION_SYNTAX, "#CS DEF needs a name: #CS DEF [name] [..]",
                        stmt.pos)


def _pattern(cur: Cursor, stmt: Instruction) -> None:
    sub = _sub(cur, "PATTERN", ("BEGIN", "END", "DELETE", "CALL"))
    if sub == "CALL":
        stmt.kind = InstructionKind.PATTERN_CALL
    elif sub == "BEGIN":
        stmt.kind = InstructionKind.PATTERN_BEGIN
        value, pos = _id(cur, "#PATTERN BEGIN")
        stmt.values, stmt.value_pos = (value,), (pos,)
    elif sub == "END":
        stmt.kind = InstructionKind.PATTERN_END
    else:
        stmt.kind = InstructionKind.PATTERN_DELETE
        cur.skip_ws()
        if cur.startswith("ALL"):
            cur.pos += 3
            stmt.all = True
        else:
            value, pos = _id(cur, "#PATTERN DELETE")
            stmt.values, stmt.value_pos = (value,), (pos,)


def _at(cur: Cursor, stmt: Instruction) -> None:
    stmt.kind = InstructionKind.AT
    stmt.values, stmt.value_pos = _list(cur, "#AT", (3, 6), NcErrorId.PATTERN_SYNTAX)


def _file(cur: Cursor, stmt: Instruction) -> None:
    stmt.kind = InstructionKind.FILE_NAME
    _sub(cur, "FILE", ("NAME",))
    open_pos = _open(cur, "'[MSG=\"<file>\"]' expected after #FILE NAME")
    cur.skip_ws()
    if not cur.startswith("MSG"):
        raise cur.error(NcErrorId.INSTRUCTION_SYNTAX, "MSG=\"<file>\" expected in #FILE NAME [..]")
    cur.pos += 3
    cur.skip_ws()
    if cur.peek() != "=":
        raise cur.error(NcErrorId.INSTRUCTION_SYNTAX, "'=' expected after MSG")
    cur.pos += 1
    cur.skip_ws()
    if cur.peek() != '"':
        raise cur.error(NcErrorId.INSTRUCTION_SYNTAX, "the file name is a string: MSG=\"<file>\"")
    close = cur.text.find('"', cur.pos + 1)
    if close < 0:
        raise cur.error(NcErrorId.STRING_NOT_CLOSED, "string without closing '\"'")
    stmt.name = cur.text[cur.pos + 1:close].strip()
    stmt.text_pos = cur.pos
    if not stmt.name:
        raise cur.error(NcErrorId.INSTRUCTION_SYNTAX, "#FILE NAME: the file name is empty")
    cur.pos = close + 1
    ExpressionParser(cur).expect("]", open_pos)


def _msg(cur: Cursor, stmt: Instruction) -> None:
    stmt.kind = InstructionKind.MSG
    cur.skip_ws()
    if cur.startswith("SAVE"):
        cur.pos += 4
        stmt.kind = InstructionKind.MSG_SAVE
        cur.skip_ws()
        if cur.startswith("EXCLUSIVE"):
            cur.pos += 9
            stmt.exclusive = True
    open_pos = _open(cur, "'[\"<text>\", ...]' expected after #MSG")
    parser = ExpressionParser(cur)
    cur.skip_ws()
    stmt.text_pos = cur.pos
    stmt.text = parser.parse()
    values: list[Node] = []
    positions: list[int] = []
    cur.skip_ws()
    while cur.peek() == ",":
        cur.pos += 1
        cur.skip_ws()
        positions.append(cur.pos)
        values.append(parser.parse())
        cur.skip_ws()
    parser.expect("]", open_pos)
    stmt.values, stmt.value_pos = tuple(values), tuple(positions)


def _on_off(
    word: str, kind: InstructionKind, options: dict[str, bool] | None,
) -> Callable[[Cursor, Instruction], None]:
    def parse(cur: Cursor, stmt: Instruction) -> None:
        stmt.kind = kind
        stmt.on = _sub(cur, word, ("ON", "OFF")) == "ON"
        if options is not None and stmt.on:
            stmt.options = _options(cur, f"#{word} ON", options)
        elif kind == InstructionKind.TRAFO and stmt.on:
            cur.skip_ws()
            if cur.peek() == "[":  # #TRAFO ON [<id>]: the transformation of the machine
                stmt.values, stmt.value_pos = _list(cur, "#TRAFO ON", (1,))
    return parse


# #ORI MODE [..]: the 5-axis modes; VECTOR_ABC / VECTOR_IJK are ISG's robot (6-axis) ones
ORI_MODES = ("VECTOR_2DOF", "ANGLE")
_ORI_MODES_6DOF = ("VECTOR_ABC", "VECTOR_IJK")


def _ori(cur: Cursor, stmt: Instruction) -> None:
    """``#ORI MODE [VECTOR_2DOF]`` / ``#ORI MODE [ANGLE]`` (ISG programming manual,
    "Programming and configuration of 5-axis kinematics (#ORI MODE)")."""
    stmt.kind = InstructionKind.ORI_MODE
    _sub(cur, "ORI", ("MODE",))
    open_pos = _open(cur, f"'[{'|'.join(ORI_MODES)}]' expected after #ORI MODE")
    cur.skip_ws()
    pos = cur.pos
    m = cur.match(IDENT)
    name = m.group() if m is not None else ""
    if name in _ORI_MODES_6DOF:
        raise cur.error(NcErrorId.INSTRUCTION_NOT_SUPPORTED,
                        f"#ORI MODE [{name}] is for 6-axis (robot) kinematics; this channel's "
                        "is a 5-axis one: VECTOR_2DOF or ANGLE", pos)
    if name not in ORI_MODES:
        cur.pos = pos
        raise cur.error(NcErrorId.INSTRUCTION_SYNTAX,
                        f"#ORI MODE needs {' or '.join(ORI_MODES)}, found '{cur.word_text()}'",
                        pos)
    stmt.name = name
    ExpressionParser(cur).expect("]", open_pos)


def _slope(cur: Cursor, stmt: Instruction) -> None:
    stmt.kind = InstructionKind.SLOPE
    open_pos = _open(cur, f"'[TYPE=<{'|'.join(SLOPE_TYPES)}>]' expected after #SLOPE")
    cur.skip_ws()
    if not cur.startswith("TYPE"):
        raise cur.error(NcErrorId.INSTRUCTION_SYNTAX, "TYPE= expected in #SLOPE [..]")
    cur.pos += 4
    cur.skip_ws()
    if cur.peek() != "=":
        raise cur.error(NcErrorId.INSTRUCTION_SYNTAX, "'=' expected after TYPE")
    cur.pos += 1
    cur.skip_ws()
    pos = cur.pos
    m = cur.match(IDENT)
    if m is None or m.group() not in SLOPE_TYPES:
        cur.pos = pos
        raise cur.error(NcErrorId.INSTRUCTION_SYNTAX,
                        f"#SLOPE TYPE must be {', '.join(SLOPE_TYPES)}, found '{cur.word_text()}'")
    stmt.name = m.group()
    ExpressionParser(cur).expect("]", open_pos)


_PARSERS = {
    "CS": _cs, "PATTERN": _pattern, "AT": _at, "FILE": _file, "MSG": _msg,
    "TRAFO": _on_off("TRAFO", InstructionKind.TRAFO, None),
    "HSC": _on_off("HSC", InstructionKind.HSC, HSC_OPTIONS),
    "FILTER": _on_off("FILTER", InstructionKind.FILTER, FILTER_OPTIONS),
    "SLOPE": _slope, "ORI": _ori,
}
