"""Axis exchange: ``#AX RELEASE`` and ``#AX REQUEST`` (ISG syntax, restricted).

* ``#AX RELEASE [X, Y]``, ``#AX RELEASE NBR [2, V.L.N]``, ``#AX RELEASE ALL`` release
  axes of the channel (by name, by logical axis number, all). An axis that is not, or
  no longer, in the channel is passed over without error.
* ``#CALL AX [...]`` and ``#PUT AX [...]`` are ISG's older spellings of ``#AX REQUEST``
  and ``#AX RELEASE`` and take the same lists.
* ``#AX REQUEST [X, 1, 0] [Y, 2, 1]`` requests axes by name, logical axis number and
  axis index in the channel (from 0). This kernel has no axis management shared
  between channels: an axis can only come back into its own channel, at its own index
  and under its own name. An axis already in the channel is passed over.

Each command stands alone in its NC line (an N number and a label may precede it).
The released axes are modal (``ModalState.released_axes``); a word of a released axis
is an error (``BlockExecutor``). A command that moves at least one axis gives a Block
with ``axis_exchange`` (no motion, the path stops); one that moves none gives nothing.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from typing import TypeVar

from .blocks import AxisExchangeKind
from .errors import NcErrorId
from .evaluation import Env, evaluate_number
from .expressions import ExpressionParser, Node
from .lexer import IDENT, Cursor
from .statements import AxisCommand, AxisRef

# "#AX" where it does not start the line (another word before it)
AX_WORD = re.compile(r"#[ \t]*AX\b")


def parse_axis_command(cur: Cursor, hash_pos: int, number: int | None,
                       sub: str | None = None) -> AxisCommand:
    """The ``#AX`` command whose ``#`` is at ``hash_pos``; the cursor stands after AX
    (``sub`` given: after ``#CALL AX`` / ``#PUT AX``, which mean REQUEST / RELEASE)."""
    if sub is None:
        cur.skip_ws()
        m = cur.match(IDENT)
        sub = m.group() if m is not None else ""
    if sub == "RELEASE":
        kind = AxisExchangeKind.RELEASE
        axes = _release_axes(cur)
    elif sub == "REQUEST":
        kind = AxisExchangeKind.REQUEST
        axes = _request_axes(cur)
    else:
        shown = sub or cur.word_text()
        message = f"#AX {shown} is not supported yet" if shown else \
            "#AX needs RELEASE or REQUEST"
        raise cur.error(NcErrorId.INSTRUCTION_NOT_SUPPORTED, message, hash_pos)
    if not cur.at_end():
        raise cur.error(
            NcErrorId.AXIS_COMMAND_NOT_ALONE,
            f"#AX {sub} must stand alone in its NC line, found '{cur.word_text()}'",
        )
    return AxisCommand(kind, cur.line, hash_pos, axes, number)


def _release_axes(cur: Cursor) -> tuple[AxisRef, ...] | None:
    cur.skip_ws()
    m = IDENT.match(cur.up, cur.pos)
    word = m.group() if m is not None else ""
    if word == "ALL":
        cur.pos += len(word)
        return None
    if word == "NBR":
        cur.pos += len(word)
        return tuple(AxisRef(pos, number=node, number_pos=pos)
                     for node, pos in _list(cur, _expression, "#AX RELEASE NBR"))
    return tuple(AxisRef(pos, name=name) for name, pos in _list(cur, _name, "#AX RELEASE"))


def _request_axes(cur: Cursor) -> tuple[AxisRef, ...]:
    parser = ExpressionParser(cur)
    refs = []
    while True:
        open_pos = _open(cur, "#AX REQUEST")
        name, name_pos = _name(cur)
        parser.expect(",")
        number, number_pos = _expression(cur)
        parser.expect(",")
        index, index_pos = _expression(cur)
        parser.expect("]", open_pos)
        refs.append(AxisRef(name_pos, name, number, number_pos, index, index_pos))
        cur.skip_ws()
        if cur.peek() != "[":
            return tuple(refs)


def _open(cur: Cursor, after: str) -> int:
    """Consume the '[' of a list; its position."""
    cur.skip_ws()
    if cur.peek() != "[":
        found = f"'{cur.word_text()}'" if cur.pos < cur.end else "the end of the line"
        raise cur.error(NcErrorId.EXPRESSION_SYNTAX, f"'[' expected after {after}, found {found}")
    cur.pos += 1
    return cur.pos - 1


Part = TypeVar("Part")  # what one part of a bracket list is


def _list(cur: Cursor, part: Callable[[Cursor], Part], after: str) -> list[Part]:
    """``[ part {, part} ]``."""
    open_pos = _open(cur, after)
    parts = [part(cur)]
    cur.skip_ws()
    while cur.peek() == ",":
        cur.pos += 1
        parts.append(part(cur))
        cur.skip_ws()
    ExpressionParser(cur).expect("]", open_pos)
    return parts


def _name(cur: Cursor) -> tuple[str, int]:
    cur.skip_ws()
    pos = cur.pos
    m = cur.match(IDENT)
    if m is None:
        found = f"'{cur.word_text()}'" if cur.pos < cur.end else "the end of the line"
        raise cur.error(NcErrorId.EXPRESSION_SYNTAX, f"axis name expected, found {found}")
    return m.group(), pos


def _expression(cur: Cursor) -> tuple[Node, int]:
    cur.skip_ws()
    pos = cur.pos
    return ExpressionParser(cur).parse(), pos


# ------------------------------------------------------------------ execution


def moved_axes(stmt: AxisCommand, env: Env, axes: tuple[str, ...],
               numbers: tuple[int, ...], released: frozenset[int]) -> tuple[int, ...]:
    """Channel axis indices that ``stmt`` takes out of the channel (RELEASE: those still
    in it) or brings back (REQUEST: those released), in programmed order, no duplicates.

    Every axis of the command is checked before anything changes (an error leaves the
    channel's axes as they were).
    """
    wanted: list[int | None]
    if stmt.axes is None:  # RELEASE ALL
        wanted = list(range(len(axes)))
    elif stmt.kind == AxisExchangeKind.RELEASE:
        wanted = [_released(ref, stmt, env, axes, numbers) for ref in stmt.axes]
    else:
        wanted = [_requested(ref, stmt, env, axes, numbers) for ref in stmt.axes]
    out = stmt.kind == AxisExchangeKind.RELEASE
    moved: list[int] = []
    for k in wanted:
        if k is not None and k not in moved and (k not in released) == out:
            moved.append(k)
    return tuple(moved)


def _released(ref: AxisRef, stmt: AxisCommand, env: Env, axes: tuple[str, ...],
              numbers: tuple[int, ...]) -> int | None:
    """Channel index of a RELEASE axis; None for an axis the channel does not have."""
    if ref.name is not None:
        return axes.index(ref.name) if ref.name in axes else None
    assert ref.number is not None  # RELEASE NBR: the parser gives each axis its number
    number = _integer(ref.number, 1, "axis number", stmt, env, ref.number_pos)
    return numbers.index(number) if number in numbers else None


def _requested(ref: AxisRef, stmt: AxisCommand, env: Env, axes: tuple[str, ...],
               numbers: tuple[int, ...]) -> int:
    """Channel index of a REQUEST axis; it must be the channel's own axis, unchanged."""
    err = stmt.line.error
    # REQUEST: the parser gives each axis its name, number and index
    assert ref.number is not None and ref.index is not None
    number = _integer(ref.number, 1, "axis number", stmt, env, ref.number_pos)
    index = _integer(ref.index, 0, "axis index", stmt, env, ref.index_pos)
    unsupported = NcErrorId.AXIS_EXCHANGE_NOT_SUPPORTED
    if number not in numbers:
        raise err(unsupported, "axis exchange between channels is not supported: "
                  f"axis {number} does not belong to this channel", ref.number_pos)
    k = numbers.index(number)
    if index != k:
        raise err(unsupported, "axis exchange between channels is not supported: "
                  f"axis {number} ({axes[k]}) has the index {k} in this channel, not {index}",
                  ref.index_pos)
    if ref.name != axes[k]:
        if ref.name in axes:
            raise err(unsupported, f"axis name {ref.name} belongs to axis "
                      f"{numbers[axes.index(ref.name)]} of this channel, not to axis {number}",
                      ref.pos)
        raise err(unsupported, "axis exchange between channels is not supported: "
                  f"axis {number} is named {axes[k]} in this channel, not {ref.name}", ref.pos)
    return k


def _integer(node: Node, lowest: int, what: str, stmt: AxisCommand, env: Env, pos: int) -> int:
    value = evaluate_number(node, env, stmt.line, pos)
    if value != int(value) or not lowest <= value <= 0xFFFFFFFF:
        raise stmt.line.error(NcErrorId.INVALID_AXIS_NUMBER,
                              f"{what} {value:g} must be an integer >= {lowest}", pos)
    return int(value)
