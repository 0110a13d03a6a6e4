"""Running the contour look-ahead commands (ISG FCT-C40) when decoding reaches them.

``contour`` parses ``#CONTOUR LOOKAHEAD LOG ...`` and ``#DISTANCE PROG START CLEAR``;
here a parsed command is checked against the running decoder (the channel's contour
look-ahead function, an open ``#RT WHILE``, tool radius compensation), its PARAM is
evaluated, the log area of the modal state moves, and the command becomes a Block
without motion (``contour_block``, also used for the real-time loop markers).
"""

from __future__ import annotations

from .blocks import Block, Compensation, ContourCommand, ContourKind, StopKind, next_log_area
from .call_stack import CallFrame
from .construct import make_block, make_source
from .errors import NcErrorId
from .evaluation import evaluate_number
from .running_decoder import RunningDecoder
from .source import LogicalLine
from .statements import ContourStatement, StmtKind

NOT_ENABLED = ("#CONTOUR LOOKAHEAD needs the contour look-ahead function: add "
               "FCT_CONTOUR_LAH to the channel's interpolator_function (P-CHAN-00650)")
CLEAR_IN_RT_LOOP = "#CONTOUR LOOKAHEAD LOG CLEAR is not allowed inside #RT WHILE"
CLEAR_WITH_COMPENSATION = ("#CONTOUR LOOKAHEAD LOG CLEAR is not allowed while tool radius "
                           "compensation (G41/G42) is active: program it after G40")


def execute_contour(stmt: ContourStatement, decoder: RunningDecoder) -> Block:
    """Run a contour command: its Block; LOG commands move the log area.

    ``decoder`` is the running Decoder (its variables, ``contour_lookahead``, frames,
    modal state). Everything is checked before the modal state changes.
    """
    kind = stmt.kind
    if kind != ContourKind.DISTANCE_CLEAR and not decoder.contour_lookahead:
        raise stmt.line.error(NcErrorId.CONTOUR_LOOKAHEAD_NOT_ENABLED, NOT_ENABLED, stmt.pos)
    if kind == ContourKind.LOG_CLEAR and inside_rt_loop(decoder.frames):
        raise stmt.line.error(NcErrorId.CONTOUR_CLEAR_IN_RT_LOOP, CLEAR_IN_RT_LOOP, stmt.pos)
    if kind == ContourKind.LOG_CLEAR and decoder.modal.compensation != Compensation.OFF:
        # Flush and wait needs the path to end here; tool radius compensation cannot end
        # an offset element before it knows the next one (it would deselect and jump).
        raise stmt.line.error(NcErrorId.CONTOUR_CLEAR_WITH_COMPENSATION,
                              CLEAR_WITH_COMPENSATION, stmt.pos)
    param = None
    if stmt.param is not None:
        param = evaluate_number(stmt.param, decoder, stmt.line, stmt.param_pos)
    modal = decoder.modal
    modal.contour_log_area = next_log_area(modal.contour_log_area, kind)
    return contour_block(stmt.line, stmt.pos, stmt.number, decoder.manual,
                         ContourCommand(kind, param))


def inside_rt_loop(frames: list[CallFrame]) -> bool:
    """True when a ``#RT WHILE`` is open in any frame (a subprogram called from inside
    a real-time loop runs inside it too)."""
    return any(entry.kind == StmtKind.RT_WHILE for frame in frames for entry in frame.control)


def contour_block(line: LogicalLine, pos: int, number: int | None, manual: bool,
                  command: ContourCommand) -> Block:
    """A Block without motion carrying ``command``, at ``pos`` (the '#') of ``line``."""
    line_no, column = line.locate(pos)
    return make_block(make_source(line.file, line_no, column, line.offset), number, None,
                      0.0, StopKind.NONE, (), None, None, manual, None, command)
