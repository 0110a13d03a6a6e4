"""ISG's spindle-specific syntax ``S[...]`` of the main spindle (issue 39, departure 5).

``S[M3 REV1000]``, ``S[REV100 POS45 M19 M3]``, ``S[M5 H20 M8]``: the bracket attached
to the spindle name holds the spindle's commands (IS/tf5200_programming_manual/
208178187.html). Each is turned into the word the plain block form has, so the two forms
share one path (same PLC handshake, same objects, same errors):

- ``M3``/``M4``/``M5``/``M19`` and user ``M<n>`` -> an M word, ``H<n>`` -> an H word;
- ``REV<expr>`` (or ``REV=<expr>``) -> the S word (a negative one is ISG's 20991);
- ``POS<expr>`` (or ``POS=<expr>``) -> ``S.POS`` (twice is ISG's 20851).

The other keywords ISG lists (G74, G167, G130, G135/G136/G137, CALLAX, PUTAX,
GET_DYNAMIC_DATA, FEED_LINK, OVERRIDE) need spindle parts the twin does not model: each
is refused with 20500 naming it. A D word is ISG's 21243, anything else ISG's 21035.
``\\`` (ISG's separator for a command over several lines) is skipped.

``S[`` begins this syntax only when a spindle keyword follows the bracket; otherwise
``S[expr]`` stays the speed as an expression (``S[500 * 2]``), as before.
"""

from __future__ import annotations

import re

from .errors import NcErrorId
from .expressions import ExpressionParser
from .lexer import Cursor
from .statements import NcBlock, Word, WordKind

# a keyword of the bracket (not the start of a function such as MAX[..] or ABS[..])
_KEYWORD = re.compile(r"[ \t]*(REV|POS|GET_DYNAMI[CK]_DATA|CALLAX|PUTAX|FEED_LINK|OVERRIDE"
                      r"|[MHGD]|\\)(?![A-Z_.])")
_NEXT = re.compile(r"[ \t]*([A-Z_][A-Z0-9_]*|\S)")
_NOT_MODELLED = frozenset({"CALLAX", "PUTAX", "GET_DYNAMIC_DATA", "GET_DYNAMIK_DATA",
                           "FEED_LINK", "OVERRIDE"})
_NOT_MODELLED_G = {74: "G74 (homing the spindle)", 167: "G167 (spindle override 100 %)",
                   130: "G130 (acceleration weighting)", 135: "G135 (feedforward)",
                   136: "G136 (feedforward weighting)", 137: "G137 (feedforward off)"}
# S[ or S2[: a spindle's bracket (one cheap test for every S word of the general path)
SPINDLE_BRACKET = re.compile(r"S([0-9]*)[ \t]*\[")
_G_NUMBER = re.compile(r"[ \t]*=?[ \t]*([0-9]+)(?![0-9.])")


def spindle_bracket(cur: Cursor, block: NcBlock, letters: set[str], pos: int) -> bool:
    """At ``S[`` or ``S<n>[`` (``SPINDLE_BRACKET`` matched at ``pos``): parse the spindle
    bracket into ``block`` and return True; False when it is the speed's bracket
    expression (``S[500 * 2]``). ``S2[...]`` is ISG's 20180: the channel has one spindle."""
    m = SPINDLE_BRACKET.match(cur.up, pos)
    assert m is not None  # checked by the caller
    if m.group(1):
        raise cur.error(NcErrorId.UNKNOWN_SPINDLE_NAME,
                        f"unknown spindle name 'S{m.group(1)}': the channel's spindle is S", pos)
    if _KEYWORD.match(cur.up, m.end()) is None:
        return False
    parse_spindle_syntax(cur, block, letters, pos)
    return True


def parse_spindle_syntax(cur: Cursor, block: NcBlock, letters: set[str], pos: int) -> None:
    """Parse ``S[...]`` at ``pos`` into ``block``'s words (the cursor ends after ``]``)."""
    if "S[" in letters:
        raise cur.error(NcErrorId.WORD_REPEATED, "S[...] programmed twice in one block", pos)
    cur.pos = cur.up.index("[", pos) + 1
    while True:
        cur.skip_ws()
        if cur.pos >= cur.end:
            raise cur.error(NcErrorId.EXPRESSION_SYNTAX, "']' expected: S[ is not closed", pos)
        if cur.peek() == "]":
            cur.pos += 1
            letters.add("S[")
            return
        _command(cur, block, letters)


def _command(cur: Cursor, block: NcBlock, letters: set[str]) -> None:
    at = cur.pos
    m = _KEYWORD.match(cur.up, at)
    if m is None:
        n = _NEXT.match(cur.up, at)
        word = n.group(1) if n else cur.peek()
        raise cur.error(NcErrorId.SPINDLE_COMMAND_UNKNOWN,
                        f"'{word}' is not a command of the spindle sequence S[...]", at)
    word = m.group(1)
    cur.pos = m.end()
    if word == "\\":
        return
    if word in _NOT_MODELLED:
        raise cur.error(NcErrorId.INSTRUCTION_NOT_SUPPORTED,
                        f"{word} in S[...] is not supported: the twin's spindle has no "
                        "such part", at)
    if word == "D":
        raise cur.error(NcErrorId.D_IN_SPINDLE_SYNTAX,
                        "D is not allowed inside the main spindle's S[...]: program it "
                        "outside the bracket", at)
    if word == "G":
        g = _G_NUMBER.match(cur.up, cur.pos)
        number = int(g.group(1)) if g else -1
        if number in _NOT_MODELLED_G:
            raise cur.error(NcErrorId.INSTRUCTION_NOT_SUPPORTED,
                            f"{_NOT_MODELLED_G[number]} in S[...] is not supported: the "
                            "twin's spindle has no such part", at)
        raise cur.error(NcErrorId.SPINDLE_COMMAND_UNKNOWN,
                        f"'{cur.word_text(at)}' is not a command of the spindle sequence "
                        "S[...]", at)
    cur.skip_ws()
    if cur.peek() == "=" and cur.peek(1) != "=":
        cur.pos += 1
        cur.skip_ws()
    if cur.pos >= cur.end or cur.peek() == "]" or _KEYWORD.match(cur.up, cur.pos):
        raise cur.error(NcErrorId.MISSING_VALUE, f"value expected after '{word}' in S[...]",
                        at)
    value = ExpressionParser(cur).parse()
    if word == "M":
        block.items.append(Word(WordKind.M, "M", value, at))
    elif word == "H":
        block.items.append(Word(WordKind.H, "H", value, at))
    elif word == "REV":
        if "S" in letters:
            raise cur.error(NcErrorId.WORD_REPEATED, "the spindle speed (S, REV) programmed "
                            "twice in one block", at)
        block.items.append(Word(WordKind.SPINDLE_REV, "REV", value, at))
        letters.add("S")
    else:  # POS
        if "S.POS" in letters:
            raise cur.error(NcErrorId.SPINDLE_POS_TWICE, "the spindle position (POS, S.POS) "
                            "programmed twice in one block", at)
        block.items.append(Word(WordKind.SPINDLE_POS, "POS", value, at))
        letters.add("S.POS")
