"""Logical line -> statement: NC blocks, control statements and #-instructions.

An NC line is ``[Nnn[:]] [[LABEL]] item item ...`` where an item is an address word
(``X10``, ``X-.5``, ``X[expr]``, ``XV.L.A``, ``X-V.L.A``), an assignment
(``V.L.A = expr``), a subprogram call (``LL name`` local, ``L name`` file) or
``$GOTO target`` (executed last). A line whose first item is ``$KEYWORD`` is a control
statement, ``#KEYWORD`` an instruction (``#AX`` an axis exchange, ``exchange``;
``#CONTOUR`` / ``#DISTANCE`` the contour look-ahead commands, ``contour``).
Unknown letters and characters are errors, never ignored.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Mapping

from .contour import CONTOUR_WORD, parse_contour_command
from .cycle_call import CYCLE_WORD, parse_cycle_call
from .errors import NcError, NcErrorId
from .exchange import AX_WORD, parse_axis_command
from .expressions import Const, ExpressionParser, Node, VarRef
from .instructions import WORDS as INSTRUCTION_WORDS
from .instructions import Instruction, parse_instruction
from .lexer import IDENT, SIGNED_NUMBER, Cursor
from .modal import G_CODES, GGroup
from .source import LogicalLine
from .spindle_syntax import SPINDLE_BRACKET, spindle_bracket
from .statements import (
    Assign,
    AxisCommand,
    Call,
    ContourStatement,
    Control,
    Goto,
    NcBlock,
    StmtKind,
    Word,
    WordKind,
)
from .variables import Value

_N_WORD = re.compile(r"N[ \t]*([-+]?[0-9.]*)([ \t]*:)?")
_LABEL = re.compile(r"\[[ \t]*([A-Z0-9_]+)[ \t]*\]")
_KEYWORD = re.compile(r"\$([A-Z]*)")
_DIRECTIVE = re.compile(r"#[ \t]*([A-Z_]*)")
_OLD_AX = {"CALL": "REQUEST", "PUT": "RELEASE"}
_AX_AFTER = re.compile(r"AX\b")
_GOTO_N = re.compile(r"N[ \t]*([0-9]+)[ \t]*:?")

# $KEYWORD -> statement kind; $GOTO is an item of an NC block
_CONTROL = {
    "IF": StmtKind.IF, "ELSEIF": StmtKind.ELSEIF, "ELSE": StmtKind.ELSE,
    "ENDIF": StmtKind.ENDIF, "WHILE": StmtKind.WHILE, "ENDWHILE": StmtKind.ENDWHILE,
    "FOR": StmtKind.FOR, "ENDFOR": StmtKind.ENDFOR, "REPEAT": StmtKind.REPEAT,
    "UNTIL": StmtKind.UNTIL, "SWITCH": StmtKind.SWITCH, "CASE": StmtKind.CASE,
    "DEFAULT": StmtKind.DEFAULT, "BREAK": StmtKind.BREAK, "CONTINUE": StmtKind.CONTINUE,
    "ENDSWITCH": StmtKind.ENDSWITCH,
}
_WITH_CONDITION = frozenset({StmtKind.IF, StmtKind.ELSEIF, StmtKind.WHILE, StmtKind.UNTIL,
                             StmtKind.SWITCH})
# G functions followed by "= <expr>": G133/G134 (weighting), G159 (zero offset group)
_ASSIGNED_G = {133.0: WordKind.WEIGHTING, 134.0: WordKind.WEIGHTING,
               159.0: WordKind.ZERO_OFFSET_INDEX}
_NOT_YET = frozenset({"DO", "ENDDO"})  # known ISG keywords of later issues
# enhanced look-ahead (MTC200 names): the switches and the parameters set with '='
LOOK_AHEAD_SWITCHES = {"LA_ON": 1.0, "LA_OFF": 0.0}
LOOK_AHEAD_PARAMS = frozenset({"METB", "VFBT", "BBTRC"})
_LOOK_AHEAD_INITIALS = frozenset("LMVB")

WordTable = Mapping[str, tuple[WordKind, int]]
# words a block may hold several of (G and M of other groups, H of other numbers)
_REPEATABLE = frozenset({WordKind.G, WordKind.M, WordKind.H})
# the syntax check's handler of an error in an item of an NC block: (error, start of the
# item) -> where parsing goes on (a position, or the line with the bad term blanked, to
# be parsed from the item's start); raises to end the line
ItemErrorHandler = Callable[[NcError, int], "int | LogicalLine"]


def word_table(axes: tuple[str, ...], orientation: bool = False
               ) -> dict[str, tuple[WordKind, int]]:
    """Address letter -> (meaning, axis index) for a channel with ``axes``.
    ``orientation`` (a channel with a kinematic chain): A, B and C are words even when
    no axis has the name, for ``#ORI MODE [VECTOR_2DOF]`` (outside it such a word is
    "not an axis of this channel", 21220, as before)."""
    index = {name: k for k, name in enumerate(axes)}
    table = {
        "F": (WordKind.FEED, -1), "S": (WordKind.SPINDLE, -1), "T": (WordKind.TOOL, -1),
        "D": (WordKind.TOOL_OFFSET, -1), "G": (WordKind.G, -1), "M": (WordKind.M, -1),
        "R": (WordKind.RADIUS, -1), "H": (WordKind.H, -1),
        "I": (WordKind.OFFSET, index.get("X", -1)),
        "J": (WordKind.OFFSET, index.get("Y", -1)),
        "K": (WordKind.OFFSET, index.get("Z", -1)),
        "X": (WordKind.AXIS, -1),  # X is also the dwell time word of G4
    }
    if orientation:
        for letter in "ABC":
            table[letter] = (WordKind.AXIS, -1)
    for name, k in index.items():
        table[name] = (WordKind.AXIS, k)
    return table


RESERVED_LETTERS = frozenset("NGMFSTDLIJKRVH")
_SPINDLE_POS = re.compile(r"S\.POS(?![A-Z0-9_])")  # the spindle's position word (M19)


class LineParser:
    """Parses the logical lines of one channel (the word table depends on its axes)."""

    def __init__(self, table: WordTable) -> None:
        self.table = table

    # ------------------------------------------------------------ entry

    def parse(
        self, line: LogicalLine, on_error: ItemErrorHandler | None = None
    ) -> NcBlock | Control | AxisCommand | ContourStatement | Instruction:
        """The statement of one logical line (raises NcError on a syntax error).

        ``on_error`` (the syntax check): an error in an item of an NC block is handed
        to it with the item's start; it returns where parsing goes on (after the
        dropped term) or raises. Parsing thus goes on in one pass, whatever the number
        of errors in a line (re-parsing the line after each error was quadratic)."""
        cur = Cursor(line)
        cur.skip_ws()
        number = self._block_number(cur, None)
        cur.skip_ws()
        if cur.peek() == "[":
            m = cur.match(_LABEL)
            if m is None:
                raise cur.error(NcErrorId.UNKNOWN_WORD, f"unknown word '{cur.word_text()}'")
            cur.skip_ws()
        c = cur.peek()
        if c == "$" and not cur.up.startswith("$GOTO", cur.pos):
            return self._control(cur, number)
        if c == "#":
            return self._directive(cur, number)
        return self._block(cur, number, on_error)

    # ------------------------------------------------------------ pieces

    def _block_number(self, cur: Cursor, current: int | None) -> int | None:
        if cur.peek() != "N":
            return current
        pos = cur.pos
        m = cur.match(_N_WORD)
        assert m is not None  # at an 'N' (checked above): the rest of the pattern is optional
        digits = m.group(1)
        if current is not None:
            raise cur.error(NcErrorId.BLOCK_NUMBER_TWICE, "block number N programmed twice", pos)
        if not digits.isdigit():
            if not digits:
                raise cur.error(NcErrorId.MISSING_VALUE, "block number expected after 'N'", pos)
            raise cur.error(
                NcErrorId.INVALID_BLOCK_NUMBER,
                f"block number N{digits} is not a non-negative integer", pos,
            )
        return int(digits)

    def _control(self, cur: Cursor, number: int | None) -> Control:
        pos = cur.pos
        m = cur.match(_KEYWORD)
        assert m is not None  # called at a '$': the rest of the pattern is optional
        word = m.group(1)
        kind = _CONTROL.get(word)
        if kind is None:
            if word in _NOT_YET:
                raise cur.error(
                    NcErrorId.INSTRUCTION_NOT_SUPPORTED, f"${word} is not supported yet", pos
                )
            raise cur.error(
                NcErrorId.UNKNOWN_CONTROL_KEYWORD, f"unknown control statement '${word}'", pos
            )
        stmt = Control(kind, cur.line, pos, number=number)
        expr = ExpressionParser(cur)
        if kind in _WITH_CONDITION:
            stmt.expr = expr.parse()
            if kind == StmtKind.IF and cur.up.startswith("$GOTO", _skip(cur)):
                cur.skip_ws()
                stmt.kind = StmtKind.IF_GOTO
                stmt.goto = self._goto(cur)
        elif kind == StmtKind.FOR:
            stmt.target = expr.variable()
            expr.expect("=")
            stmt.expr = expr.parse()
            expr.expect(",")
            stmt.end = expr.parse()
            cur.skip_ws()
            if cur.peek() == ",":
                cur.pos += 1
                stmt.step = expr.parse()
        elif kind == StmtKind.CASE:
            values = [expr.parse()]
            cur.skip_ws()
            while cur.peek() == ",":
                cur.pos += 1
                values.append(expr.parse())
                cur.skip_ws()
            stmt.values = tuple(values)
        self._line_end(cur, f"${word}")
        return stmt

    def _directive(
        self, cur: Cursor, number: int | None
    ) -> Control | AxisCommand | ContourStatement | Instruction:
        pos = cur.pos
        m = cur.match(_DIRECTIVE)
        assert m is not None  # called at a '#': the rest of the pattern is optional
        word = m.group(1)
        if word == "AX":
            return parse_axis_command(cur, pos, number)
        if word in _OLD_AX:  # #CALL AX / #PUT AX: ISG's older axis exchange spellings
            cur.skip_ws()
            if cur.match(_AX_AFTER) is not None:
                return parse_axis_command(cur, pos, number, _OLD_AX[word])
        if word in ("CONTOUR", "DISTANCE"):
            return parse_contour_command(cur, pos, word, number)
        if word in INSTRUCTION_WORDS:
            return parse_instruction(cur, word, pos, number)
        if word == "VAR":
            stmt = Control(StmtKind.VAR, cur.line, pos, number=number)
        elif word == "ENDVAR":
            stmt = Control(StmtKind.ENDVAR, cur.line, pos, number=number)
        elif word == "RT":
            cur.skip_ws()
            sub = cur.match(IDENT)
            if sub is not None and sub.group() == "WHILE":
                stmt = Control(StmtKind.RT_WHILE, cur.line, pos, number=number)
                if not cur.at_end():
                    stmt.expr = ExpressionParser(cur).parse()
            elif sub is not None and sub.group() == "ENDWHILE":
                stmt = Control(StmtKind.RT_ENDWHILE, cur.line, pos, number=number)
            else:
                shown = sub.group() if sub else cur.word_text()
                raise cur.error(
                    NcErrorId.INSTRUCTION_NOT_SUPPORTED, f"#RT {shown} is not supported yet", pos
                )
            word = "RT " + sub.group()
        elif word:
            raise cur.error(
                NcErrorId.INSTRUCTION_NOT_SUPPORTED, f"#{word} is not supported yet", pos
            )
        else:
            raise cur.error(NcErrorId.UNKNOWN_WORD, f"unknown word '{cur.word_text(pos)}'", pos)
        self._line_end(cur, f"#{word}")
        return stmt

    def _line_end(self, cur: Cursor, after: str) -> None:
        if cur.at_end():
            return
        if cur.peek() == "=" and cur.peek(1) != "=":
            raise cur.error(NcErrorId.EXPRESSION_SYNTAX, "'=' is an assignment; compare with ==")
        raise cur.unexpected(f"after {after}")

    def _goto(self, cur: Cursor) -> Goto:
        pos = cur.pos
        cur.pos += len("$GOTO")
        cur.skip_ws()
        m = cur.match(_GOTO_N)
        if m is not None:
            return Goto(f"N{int(m.group(1))}", pos)
        m = cur.match(_LABEL)
        if m is not None:
            return Goto(f"[{m.group(1)}]", pos)
        raise cur.error(
            NcErrorId.BAD_GOTO_TARGET,
            f"$GOTO needs Nnn or [LABEL], found '{cur.word_text()}'",
        )

    def _block(self, cur: Cursor, number: int | None,
               on_error: ItemErrorHandler | None = None) -> NcBlock:
        block = NcBlock(cur.line, number)
        letters: set[str] = set()
        table = self.table
        while not cur.at_end():
            pos = cur.pos
            try:
                self._item(cur, block, letters, table, pos)
            except NcError as error:
                if on_error is None:
                    raise
                where = on_error(error, pos)  # the term is dropped, parsing goes on
                if isinstance(where, int):
                    cur.pos = where
                else:  # the line with the term blanked, parsed again from this item on
                    cur = Cursor(where, pos)
                    block.line = where
        block.letters = frozenset(letters)
        return block

    def _item(self, cur: Cursor, block: NcBlock, letters: set[str], table: WordTable,
              pos: int) -> None:
        """Parse the item at ``pos`` into ``block`` (a letter counts in ``letters``
        only once its word is complete, so a dropped word leaves no trace)."""
        c = cur.peek()
        if c == "$":
            if not cur.up.startswith("$GOTO", pos):
                keyword = cur.match(_KEYWORD)
                assert keyword is not None  # at a '$': the rest is optional
                word = keyword.group(1)
                raise cur.error(
                    NcErrorId.UNKNOWN_CONTROL_KEYWORD,
                    f"${word} must stand at the start of its line", pos,
                )
            if block.goto is not None:
                raise cur.error(NcErrorId.WORD_REPEATED, "$GOTO programmed twice", pos)
            block.goto = self._goto(cur)
        elif c == "V" and cur.peek(1) == ".":
            block.items.append(self._assign(cur))
        elif c in _LOOK_AHEAD_INITIALS and self._look_ahead_word(cur, block):
            return
        elif c == "L":
            self._call(cur, block)
        elif c == "N":
            block.number = self._block_number(cur, block.number)
        elif c == "S" and _SPINDLE_POS.match(cur.up, pos):
            self._spindle_pos(cur, block, letters, pos)
        elif c == "S" and SPINDLE_BRACKET.match(cur.up, pos) \
                and spindle_bracket(cur, block, letters, pos):
            return  # S[M3 REV1000 ...] (S2[...]: ISG's 20180); S[expr] is the speed
        elif "A" <= c <= "Z" or c == "_":
            spec = table.get(c)
            if spec is None:
                raise cur.error(NcErrorId.UNKNOWN_WORD, f"unknown word '{cur.word_text()}'")
            kind, axis = spec
            if kind not in _REPEATABLE:
                if c in letters:
                    raise cur.error(
                        NcErrorId.WORD_REPEATED, f"{c} programmed twice in one block"
                    )
            cur.pos += 1
            if kind == WordKind.AXIS and _skip(cur) < cur.end and cur.peek() == "=" \
                    and cur.peek(1) != "=":
                cur.pos += 1  # X=<expr>: ISG's axis word with '=' ("Axis commands")
                value = self._expression_value(cur, c, pos)
            else:
                value = self._value(cur, c, pos)
            if kind == WordKind.G and value in _ASSIGNED_G and _skip(cur) < cur.end \
                    and cur.peek() == "=" and cur.peek(1) != "=":
                cur.pos += 1  # G133 = <percent> / G134 = <percent> / G159 = <index>
                block.items.append(Word(_ASSIGNED_G[value], f"G{int(value)}",
                                        ExpressionParser(cur).parse(), pos))
                return
            if kind == WordKind.G and isinstance(value, float):
                if not value.is_integer() or int(value) not in G_CODES:
                    raise cur.error(
                        NcErrorId.UNSUPPORTED_G_CODE, f"G{value:g} is not supported", pos
                    )
                if G_CODES[int(value)][0] == GGroup.DWELL:
                    block.has_g4 = True
            if kind not in _REPEATABLE:
                letters.add(c)
            block.items.append(Word(kind, c, value, pos, axis))
        elif c == "#" and AX_WORD.match(cur.up, pos):
            raise cur.error(NcErrorId.AXIS_COMMAND_NOT_ALONE,
                            "#AX must stand alone in its NC line")
        elif c == "#" and CONTOUR_WORD.match(cur.up, pos):
            directive = _DIRECTIVE.match(cur.up, pos)
            assert directive is not None  # at a '#': the rest is optional
            word = directive.group(1)
            raise cur.error(NcErrorId.CONTOUR_COMMAND_SYNTAX,
                            f"#{word} must stand alone in its NC line")
        else:
            raise cur.error(NcErrorId.UNKNOWN_WORD, f"unknown word '{cur.word_text()}'")

    def _spindle_pos(self, cur: Cursor, block: NcBlock, letters: set[str], pos: int) -> None:
        """``S.POS = <expr>``: the position (degrees) of an M19 in the same block."""
        if "S.POS" in letters:
            raise cur.error(NcErrorId.SPINDLE_POS_TWICE, "the spindle position (POS, S.POS) "
                            "programmed twice in one block", pos)
        m = _SPINDLE_POS.match(cur.up, pos)
        assert m is not None  # checked by the caller
        cur.pos = m.end()
        if _skip(cur) >= cur.end or cur.peek() != "=" or cur.peek(1) == "=":
            raise cur.error(NcErrorId.EXPRESSION_SYNTAX, "'=' expected after S.POS", pos)
        cur.pos += 1
        block.items.append(Word(WordKind.SPINDLE_POS, "S.POS", ExpressionParser(cur).parse(),
                                pos))
        letters.add("S.POS")

    def _look_ahead_word(self, cur: Cursor, block: NcBlock) -> bool:
        """``LA_ON`` / ``LA_OFF`` or ``METB|VFBT|BBTRC = <expr>`` at the cursor: parsed
        into ``block``; False when the word is none of them."""
        pos = cur.pos
        m = IDENT.match(cur.up, pos)
        if m is None:
            return False
        word = m.group()
        switch = LOOK_AHEAD_SWITCHES.get(word)
        if switch is not None:
            cur.pos = m.end()
            block.items.append(Word(WordKind.LOOK_AHEAD, word, switch, pos))
            return True
        if word not in LOOK_AHEAD_PARAMS:
            return False
        cur.pos = m.end()
        if _skip(cur) >= cur.end or cur.peek() != "=" or cur.peek(1) == "=":
            raise cur.error(NcErrorId.EXPRESSION_SYNTAX, f"'=' expected after {word}", pos)
        cur.pos += 1
        block.items.append(Word(WordKind.LOOK_AHEAD_PARAM, word, ExpressionParser(cur).parse(),
                                pos))
        return True

    def _value(self, cur: Cursor, letter: str, letter_pos: int) -> float | Node:
        cur.skip_ws()
        m = cur.match(SIGNED_NUMBER)
        if m is not None:
            number = float(m.group())
            if not math.isfinite(number):  # digits beyond the float range: 1e309, G9...9
                raise cur.error(NcErrorId.VALUE_OUT_OF_RANGE,
                                f"the value of '{letter}' ({len(m.group())} characters) is "
                                "beyond the range of a number", letter_pos)
            return number
        pos = cur.pos
        negative = False
        if cur.peek() in ("-", "+") and (cur.peek(1) == "[" or cur.up.startswith("V.", pos + 1)):
            negative = cur.peek() == "-"
            cur.pos += 1
        c = cur.peek()
        parser = ExpressionParser(cur)
        if c == "[":
            node = parser._primary()  # only the bracket, not what follows
        elif c == "V" and cur.peek(1) == ".":
            node = parser.variable()
        else:
            raise cur.error(NcErrorId.MISSING_VALUE, f"value expected after '{letter}'", letter_pos)
        if negative:
            inner = node
            node = lambda env: _negate(inner(env))
        return _word_value(node, cur, letter, pos)

    def _expression_value(self, cur: Cursor, letter: str, letter_pos: int) -> float | Node:
        """The value of ``<axis>=<expression>``: a whole expression, brackets optional."""
        if _skip(cur) >= cur.end:
            raise cur.error(NcErrorId.MISSING_VALUE, f"value expected after '{letter}='",
                            letter_pos)
        pos = cur.pos
        return _word_value(ExpressionParser(cur).parse(), cur, letter, pos)

    def _assign(self, cur: Cursor) -> Assign:
        pos = cur.pos
        parser = ExpressionParser(cur)
        target = parser.variable()
        cur.skip_ws()
        if cur.peek() != "=" or cur.peek(1) == "=":
            raise cur.error(
                NcErrorId.EXPRESSION_SYNTAX, f"'=' expected after {target.full}", pos
            )
        cur.pos += 1
        return Assign(target, parser.parse(), pos)

    def _call(self, cur: Cursor, block: NcBlock) -> None:
        pos = cur.pos
        m = IDENT.match(cur.up, pos)
        ident = m.group() if m else "L"
        local = ident == "LL"
        cur.pos += 2 if local else 1
        cur.skip_ws()
        if CYCLE_WORD.match(cur.up, cur.pos):
            call = parse_cycle_call(cur, local, pos)
        else:
            name = cur.name()
            if not name:
                raise cur.error(
                    NcErrorId.MISSING_VALUE,
                    f"subprogram name expected after '{'LL' if local else 'L'}'",
                    pos,
                )
            call = Call(local, name, pos)
        if block.call is not None:
            raise cur.error(NcErrorId.WORD_REPEATED, "two subprogram calls in one block", pos)
        block.call = call


def _skip(cur: Cursor) -> int:
    cur.skip_ws()
    return cur.pos


def _negate(value: Value) -> Value:
    """-value; a string stays a string so that the word's evaluation reports it."""
    return value if isinstance(value, str) else -value


__all__ = [
    "ItemErrorHandler", "LineParser", "RESERVED_LETTERS", "VarRef", "WordTable", "word_table",
]


def _word_value(node: Node, cur: Cursor, letter: str, pos: int) -> float | Node:
    """A word's value: a float when known at parse time (a string is TYPE_MISMATCH),
    else the node to evaluate."""
    if isinstance(node, Const):
        value = node.value
        if isinstance(value, str):
            raise cur.error(NcErrorId.TYPE_MISMATCH, f"{letter} needs a number, not a string",
                            pos)
        return float(value)
    return node
