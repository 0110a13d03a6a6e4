"""Control statements at decode time: $IF, loops, $SWITCH, $BREAK, #RT WHILE, $GOTO.

Every control statement is evaluated when the decoder reaches it; open blocks are kept
on the frame's control stack. A false condition jumps over the block to the line its
scan found (``Program.structure``, cached), so a loop does not rescan its body.

``#RT WHILE [cond]`` ... ``#RT ENDWHILE`` is a real-time loop on a real ISG kernel (the
condition is checked by the interpolator each pass). This decoder has no real-time
conditions yet: it evaluates the condition at decode time on every pass and unrolls
the loop into ordinary blocks, like ``$WHILE``. Without a condition the loop runs
until the program is reset; the decoder is lazy, so it produces blocks as long as the
caller pulls them.

A real-time loop entered while the contour look-ahead's marked area is open gets
marker Blocks at its passes (``rt_loop_markers.RtLoopMarkers``): ``run`` returns them.
They do not count as blocks for the endless-program guard.

The endless-program guard and the look for a RESET are not the loops' business: the
decoding loop counts every step of work, loops or not (``work_guard``).
"""

from __future__ import annotations

from collections.abc import Callable

from .blocks import Block
from .call_stack import CallFrame, ControlEntry
from .errors import NcError, NcErrorId
from .expressions import number, truth
from .program import Statement, Structure
from .rt_loop_markers import RtLoopMarkers
from .running_decoder import RunningDecoder
from .source import LogicalLine
from .statements import LOOPS, SPELLING, Control, Goto, StmtKind
from .variables import Value

#: a control statement's handler: (frame, statement, index after it) -> marker Block or None
Handler = Callable[[CallFrame, Control, int], Block | None]


class ControlFlow:
    """The handlers of the control statements, one per kind (dispatch table)."""

    def __init__(self, decoder: RunningDecoder) -> None:
        self.decoder = decoder
        self.markers = RtLoopMarkers(decoder)
        k = StmtKind
        self.handlers: dict[StmtKind, Handler] = {
            k.IF: self._if, k.IF_GOTO: self._if_goto, k.ELSEIF: self._else,
            k.ELSE: self._else, k.ENDIF: self._endif, k.WHILE: self._while,
            k.RT_WHILE: self._rt_while, k.ENDWHILE: self._endwhile,
            k.RT_ENDWHILE: self._endwhile, k.FOR: self._for, k.ENDFOR: self._endfor,
            k.REPEAT: self._repeat, k.UNTIL: self._until, k.SWITCH: self._switch,
            k.CASE: self._case, k.DEFAULT: self._case, k.ENDSWITCH: self._endswitch,
            k.BREAK: self._break, k.CONTINUE: self._continue, k.VAR: self._var,
            k.ENDVAR: self._endvar,
        }

    def run(self, frame: CallFrame, stmt: Control, after: int) -> Block | None:
        """Execute ``stmt`` (the line at ``frame.index``); sets the next ``frame.index``.
        Returns a real-time loop marker Block or None (the handlers return nothing else)."""
        return self.handlers[stmt.kind](frame, stmt, after)

    # ------------------------------------------------------------ helpers

    def _cond(self, stmt: Control) -> bool:
        if stmt.expr is None:  # #RT WHILE without condition
            return True
        return truth(stmt.expr(self.decoder), stmt.line, stmt.pos)

    def _structure(self, frame: CallFrame, stmt: Control, index: int) -> Structure:
        return frame.program.structure(stmt, index, frame.section.end)

    def _top(self, frame: CallFrame, *kinds: StmtKind) -> ControlEntry | None:
        if frame.control and frame.control[-1].kind in kinds:
            return frame.control[-1]
        return None

    def _mismatch(
        self, frame: CallFrame, stmt: Control, err: NcErrorId, opener: StmtKind,
    ) -> NcError:
        if frame.control:
            open_kind = frame.control[-1].kind
            return stmt.line.error(
                err, f"{SPELLING[stmt.kind]} does not match the open {SPELLING[open_kind]}",
                stmt.pos,
            )
        return stmt.line.error(err, f"{SPELLING[stmt.kind]} without {SPELLING[opener]}", stmt.pos)

    # ------------------------------------------------------------ $IF

    def _if(self, frame: CallFrame, stmt: Control, after: int) -> None:
        index = frame.index
        if self._cond(stmt):
            frame.control.append(ControlEntry(StmtKind.IF, index, stmt, after))
            frame.index = after
            return
        program = frame.program
        end = frame.section.end
        structure = self._structure(frame, stmt, index)
        for kind, k in structure.parts:
            part, part_after = program.statement(k, end)
            if kind == StmtKind.ELSE or self._cond(_control(part)):
                frame.control.append(ControlEntry(StmtKind.IF, index, stmt, part_after))
                frame.index = part_after
                return
        frame.index = structure.after

    def _if_goto(self, frame: CallFrame, stmt: Control, after: int) -> None:
        if self._cond(stmt):
            assert stmt.goto is not None  # the parser gives every IF_GOTO its $GOTO
            self.goto(frame, stmt.goto, stmt.line, frame.index)
        else:
            frame.index = after

    def _else(self, frame: CallFrame, stmt: Control, after: int) -> None:
        # reached from a branch that ran: the rest of the $IF block is skipped
        top = self._top(frame, StmtKind.IF)
        if top is not None:
            frame.control.pop()
            frame.index = self._structure(frame, top.stmt, top.index).after
        elif frame.jumped:  # a $GOTO entered the branch from outside (ISG allows it)
            frame.index = self._structure(frame, stmt, frame.index).after
        else:
            raise self._mismatch(frame, stmt, NcErrorId.ELSE_WITHOUT_IF, StmtKind.IF)

    def _endif(self, frame: CallFrame, stmt: Control, after: int) -> None:
        if self._top(frame, StmtKind.IF) is not None:
            frame.control.pop()
        elif not frame.jumped:
            raise self._mismatch(frame, stmt, NcErrorId.ENDIF_WITHOUT_IF, StmtKind.IF)
        frame.index = after

    # ------------------------------------------------------------ loops

    def _while(self, frame: CallFrame, stmt: Control, after: int) -> None:
        if self._cond(stmt):
            frame.control.append(ControlEntry(stmt.kind, frame.index, stmt, after))
            frame.index = after
        else:
            frame.index = self._structure(frame, stmt, frame.index).after

    def _rt_while(self, frame: CallFrame, stmt: Control, after: int) -> Block | None:
        """``$WHILE`` semantics; tells the markers about the test (first or re-test)."""
        index = frame.index
        entry = None
        if self._cond(stmt):
            entry = ControlEntry(stmt.kind, index, stmt, after)
            frame.control.append(entry)
            frame.index = after
        else:
            frame.index = self._structure(frame, stmt, index).after
        return self.markers.tested(frame, stmt, index, entry)

    def _endwhile(self, frame: CallFrame, stmt: Control, after: int) -> None:
        opener = StmtKind.WHILE if stmt.kind == StmtKind.ENDWHILE else StmtKind.RT_WHILE
        top = self._top(frame, opener)
        if top is None:
            raise self._mismatch(frame, stmt, NcErrorId.LOOP_END_WITHOUT_BEGIN, opener)
        frame.control.pop()
        if opener == StmtKind.RT_WHILE:
            self.markers.closed(frame, top)
        frame.index = top.index  # the loop statement tests its condition again

    def _for(self, frame: CallFrame, stmt: Control, after: int) -> None:
        env = self.decoder
        line = stmt.line
        # the parser gives every $FOR its variable, start and end
        assert stmt.target is not None and stmt.expr is not None and stmt.end is not None
        stmt.target.assign(env, stmt.expr(env))
        end = number(stmt.end(env), line, stmt.pos, "a number as $FOR end")
        step = 1.0 if stmt.step is None else number(stmt.step(env), line, stmt.pos, "a step")
        if step == 0:
            raise line.error(NcErrorId.FOR_STEP_ZERO, "$FOR step 0 never ends", stmt.pos)
        if self._in_range(stmt, end, step):
            frame.control.append(ControlEntry(StmtKind.FOR, frame.index, stmt, after, end, step))
            frame.index = after
        else:
            frame.index = self._structure(frame, stmt, frame.index).after

    def _in_range(self, stmt: Control, end: float, step: float) -> bool:
        assert stmt.target is not None  # a $FOR (see _for)
        value = number(stmt.target(self.decoder), stmt.line, stmt.pos, "a number in $FOR")
        return value <= end if step > 0 else value >= end

    def _endfor(self, frame: CallFrame, stmt: Control, after: int) -> None:
        top = self._top(frame, StmtKind.FOR)
        if top is None:
            raise self._mismatch(frame, stmt, NcErrorId.LOOP_END_WITHOUT_BEGIN, StmtKind.FOR)
        opener = top.stmt
        assert opener.target is not None  # a $FOR (see _for)
        value = number(opener.target(self.decoder), opener.line, opener.pos, "a number in $FOR")
        opener.target.assign(self.decoder, value + top.step)
        if self._in_range(opener, top.end, top.step):
            frame.index = top.body
        else:
            frame.control.pop()
            frame.index = after

    def _repeat(self, frame: CallFrame, stmt: Control, after: int) -> None:
        frame.control.append(ControlEntry(StmtKind.REPEAT, frame.index, stmt, after))
        frame.index = after

    def _until(self, frame: CallFrame, stmt: Control, after: int) -> None:
        top = self._top(frame, StmtKind.REPEAT)
        if top is None:
            raise self._mismatch(frame, stmt, NcErrorId.LOOP_END_WITHOUT_BEGIN, StmtKind.REPEAT)
        if self._cond(stmt):
            frame.control.pop()
            frame.index = after
        else:
            frame.index = top.body

    # ------------------------------------------------------------ $SWITCH

    def _switch(self, frame: CallFrame, stmt: Control, after: int) -> None:
        env = self.decoder
        assert stmt.expr is not None  # the parser gives every $SWITCH its value
        value = stmt.expr(env)
        program = frame.program
        structure = self._structure(frame, stmt, frame.index)
        target: int | None = None
        for kind, k in structure.parts:
            part, part_after = program.statement(k, frame.section.end)
            if kind == StmtKind.DEFAULT:
                target = part_after if target is None else target
                continue
            if any(_same(value, v(env)) for v in _control(part).values):
                target = part_after
                break
        if target is None:
            frame.index = structure.after
            return
        frame.control.append(ControlEntry(StmtKind.SWITCH, frame.index, stmt, target))
        frame.index = target

    def _case(self, frame: CallFrame, stmt: Control, after: int) -> None:
        # reached by falling through from the case before: nothing to do
        if self._top(frame, StmtKind.SWITCH) is None:
            raise self._mismatch(
                frame, stmt, NcErrorId.SWITCH_PART_WITHOUT_SWITCH, StmtKind.SWITCH
            )
        frame.index = after

    def _endswitch(self, frame: CallFrame, stmt: Control, after: int) -> None:
        if self._top(frame, StmtKind.SWITCH) is None:
            raise self._mismatch(
                frame, stmt, NcErrorId.SWITCH_PART_WITHOUT_SWITCH, StmtKind.SWITCH
            )
        frame.control.pop()
        frame.index = after

    # ------------------------------------------------------------ $BREAK, $CONTINUE

    def _break(self, frame: CallFrame, stmt: Control, after: int) -> Block | None:
        for n in range(len(frame.control) - 1, -1, -1):
            entry = frame.control[n]
            if entry.kind == StmtKind.SWITCH or entry.kind in LOOPS:
                left = frame.control[n:]
                del frame.control[n:]
                frame.index = self._structure(frame, entry.stmt, entry.index).after
                return self.markers.broken(frame, left)
        raise stmt.line.error(
            NcErrorId.BREAK_OUTSIDE_LOOP, "$BREAK outside a loop or $SWITCH", stmt.pos
        )

    def _continue(self, frame: CallFrame, stmt: Control, after: int) -> None:
        for n in range(len(frame.control) - 1, -1, -1):
            entry = frame.control[n]
            if entry.kind in LOOPS:
                del frame.control[n + 1:]
                # continue at the loop's closing statement, which starts the next pass
                frame.index = self._structure(frame, entry.stmt, entry.index).close
                return
        raise stmt.line.error(NcErrorId.BREAK_OUTSIDE_LOOP, "$CONTINUE outside a loop", stmt.pos)

    # ------------------------------------------------------------ #VAR

    def _var(self, frame: CallFrame, stmt: Control, after: int) -> None:
        self.decoder.declare_block(frame, stmt, after)

    def _endvar(self, frame: CallFrame, stmt: Control, after: int) -> None:
        raise stmt.line.error(NcErrorId.ENDVAR_WITHOUT_VAR, "#ENDVAR without #VAR", stmt.pos)

    # ------------------------------------------------------------ $GOTO

    def goto(self, frame: CallFrame, goto: Goto, line: LogicalLine, here: int) -> None:
        """Jump from line ``here`` to a label of the frame's section, leaving the
        control blocks the label is not in."""
        program = frame.program
        target = program.find_label(frame.section, goto.label, here)
        if target is None:
            raise line.error(NcErrorId.LABEL_NOT_FOUND, f"label {goto.label} not found", goto.pos)
        while frame.control:
            entry = frame.control[-1]
            structure = self._structure(frame, entry.stmt, entry.index)
            if entry.index < target <= structure.close:
                break
            frame.control.pop()
        frame.index = target
        frame.jumped = True


def _control(part: Statement | None) -> Control:
    """The $ELSEIF / $CASE statement of a part that ``Program.structure`` found."""
    # the scan found the keyword of a control statement with an expression there, so the
    # line parses to a Control (the syntax check keeps a failed one as dropped_control)
    assert type(part) is Control
    return part


def _same(a: Value, b: Value) -> bool:
    """$CASE comparison: equal numbers or equal strings (a string never equals a number)."""
    if isinstance(a, str) or isinstance(b, str):
        return isinstance(a, str) and isinstance(b, str) and a == b
    return a == b
