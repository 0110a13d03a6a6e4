"""The decoder: NC program text -> a lazy stream of ``Block`` objects.

``Decoder.blocks()`` is a generator: it decodes only as far as the caller pulls, so the
SDA task takes as many blocks as the look-ahead buffer has room for, and an endless
``$WHILE 1`` with motion never hangs it. Errors are raised at the point where decoding
reaches them (an error in line 900 comes after the blocks of lines 1..899).

Each line is decoded by the fast path (``fastpath``) when it is a plain motion line,
otherwise it is parsed (``parser``, cached per line) and executed: NC blocks by the
``BlockExecutor``, control statements by ``ControlFlow``. Subprograms run in frames of
their own (``L name`` loads a file through ``loader``, ``LL name`` runs a ``%L``
section); the frame stack is explicit, so recursion never touches Python's stack.

End of decoding: M2/M30 (the block is yielded with ``stop == PROGRAM_END``, nothing
after it is decoded); in a manual block also the end of the text. The end of a main
program without M2/M30 is an error, as is the end of a file subprogram without M17/M29.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Iterator, Mapping
from dataclasses import replace

from . import work_guard
from .blockexec import BlockExecutor, Flow
from .blocks import Block, LogArea
from .call_stack import MAX_CALL_DEPTH, CallFrame, CallFrameKind
from .check import (
    CHECK_FEED_MM_MIN,
    CheckAborted,
    ErrorCategory,
    ErrorReported,
    SyntaxCheck,
    categorize,
    holds_error,
    item_at,
)
from .contour_run import execute_contour
from .control import ControlFlow
from .cycle_run import call_cycle
from .declarations import declare, read_block
from .errors import DecodingCancelled, NcError, NcErrorId
from .fastpath import decoding_loop
from .instruction_run import pattern_error, run_instruction
from .instructions import Instruction
from .modal import ModalState
from .parser import RESERVED_LETTERS, LineParser, word_table
from .program import Program, Section, Statement
from .source import LogicalLine, NcText, SourceText, strip_comments
from .statements import (
    CLOSER_OF,
    OPENERS,
    SPELLING,
    Assign,
    AxisCommand,
    ContourStatement,
    Control,
    NcBlock,
    Word,
    WordKind,
)
from .technology import HSCS_MODES, Surroundings
from .variables import Scope, Value, Variable, VarType
from .zero_offset_writes import write_zero_offset

log = logging.getLogger(__name__)


class Decoder:
    """Decodes one NC text (a program, or a manual block) into Blocks.

    ``axes``: the channel's axis names in order, one upper-case letter each (I/J/K are
    the centre offsets of the axes named X/Y/Z). ``text`` is the program's text or its
    file (a ``Path``: read as a stream, page by page, ``text_pages``). ``loader(name)``
    returns the text or the file of a file subprogram and raises KeyError when there is
    none. ``tools`` maps D numbers to
    tool radii in mm (D0 is radius 0). ``modal`` is continued (and changed) when given;
    otherwise decoding starts from a fresh ``ModalState`` at position 0. Bit n-1 of
    ``skip_levels`` skips the lines marked ``/n``. ``manual`` marks the blocks as
    manual and lets the text end without M30. ``axis_numbers``: the logical axis number
    of each channel axis (default 1..n), for ``#AX RELEASE NBR`` and ``#AX REQUEST``.
    A program (not ``manual``) starts with all axes in the channel; manual blocks keep
    the axes released before (``modal.released_axes``).

    ``contour_lookahead``: the channel has the contour look-ahead function
    (FCT_CONTOUR_LAH is in the channel's interpolator functions, P-CHAN-00650); without
    it ``#CONTOUR LOOKAHEAD`` is an error. A program starts without a marked area
    (``modal.contour_log_area`` NONE); manual blocks keep the area.
    """

    def __init__(
        self,
        text: NcText,
        file: str,
        *,
        axes: tuple[str, ...],
        loader: Callable[[str], NcText],
        tools: Mapping[int, float],
        modal: ModalState | None = None,
        skip_levels: int = 1,
        manual: bool = False,
        axis_numbers: tuple[int, ...] | None = None,
        contour_lookahead: bool = False,
        check: SyntaxCheck | None = None,
        surroundings: Surroundings | None = None,
    ) -> None:
        axes = tuple(axes)
        for name in axes:
            if len(name) != 1 or not "A" <= name <= "Z" or name in RESERVED_LETTERS:
                raise ValueError(f"axis name {name!r} must be one letter other than "
                                 f"{''.join(sorted(RESERVED_LETTERS))}")
        if len(set(axes)) != len(axes):
            raise ValueError(f"axis names repeat: {axes}")
        if axis_numbers is None:
            axis_numbers = tuple(range(1, len(axes) + 1))
        axis_numbers = tuple(axis_numbers)
        if (len(axis_numbers) != len(axes) or len(set(axis_numbers)) != len(axis_numbers)
                or not all(type(n) is int and n >= 1 for n in axis_numbers)):
            raise ValueError(f"axis numbers {axis_numbers} must be distinct integers >= 1, "
                             f"one per axis of {axes}")
        if modal is None:
            modal = ModalState()
        if not modal.position_mm:
            modal.position_mm = (0.0,) * len(axes)
        elif len(modal.position_mm) != len(axes):
            raise ValueError(f"modal position has {len(modal.position_mm)} axes, "
                             f"the channel {len(axes)}")
        if not manual:  # a program starts with the channel's axes and an empty log
            modal.released_axes = frozenset()
            modal.contour_log_area = LogArea.NONE
            modal.start_program()
        elif not all(0 <= k < len(axes) for k in modal.released_axes):
            raise ValueError(f"released axes {sorted(modal.released_axes)} are not axes "
                             f"of the channel {axes}")
        self.axes = axes
        self.axis_numbers = axis_numbers
        self.manual = manual
        self.contour_lookahead = contour_lookahead
        self.check = check
        self.surroundings = surroundings or Surroundings()
        self.files_written: set[str] = set()  # #MSG SAVE files written in this run
        self._loader = loader
        self._modal = modal
        self._skip_levels = skip_levels
        chain = self.surroundings.kinematic_chain
        self.parser = LineParser(word_table(axes, orientation=chain is not None))
        self.executor = BlockExecutor(axes, tools, modal, manual, axis_numbers)
        self.executor.m_function_known = self.surroundings.m_function_known
        self.executor.kinematic_chain = chain
        self._main = Program(text, file, self.parser, skip_levels, check)
        self._files: dict[str, Program] = {}
        self.frames: list[CallFrame] = []
        self._control = ControlFlow(self)
        self.finished = False
        self._started = False
        self.own_variables: set[int] = set()  # ids of the variables this decoder declared
        # the run's owner sets this to learn of a RESET (``DecodingCancelled``)
        self.cancelled: Callable[[], bool] = _never
        # the endless-program guard's limit (work_guard): steps without a block
        limit = self.surroundings.idle_steps_max
        self.idle_steps_max = work_guard.IDLE_STEPS_MAX if limit is None else limit
        self._executed: Block | None = None  # check mode: the Block of the line's words

    def close(self) -> None:
        """Close the files of the programs read as streams (the main program and the
        file subprograms loaded); the decoder decodes nothing more after this."""
        self._main.src.close()
        for program in self._files.values():
            program.src.close()

    @property
    def source(self) -> SourceText:
        """The text of the program being decoded (``SourceText``: lines, offsets)."""
        return self._main.src

    def source_of(self, name: str) -> SourceText | None:
        """The text of file ``name`` if this decoder has loaded it (main or subprogram)."""
        if name == self._main.name:
            return self._main.src
        program = self._files.get(name)
        return None if program is None else program.src

    @property
    def modal(self) -> ModalState:
        """The modal state (the one passed in, changed as decoding goes)."""
        return self._modal

    def blocks(self) -> Iterator[Block]:
        """The decoded blocks, lazily; raises NcError where decoding meets an error."""
        if self._started:
            raise RuntimeError("Decoder.blocks() can run only once")
        self._started = True
        main = self._main
        self.frames.append(CallFrame(main, main.main, main.main.start, CallFrameKind.MAIN))
        return decoding_loop(self.axes, self.check is not None)(self)

    # ------------------------------------------------------------ variables (Env)

    def find_variable(self, scope: Scope, name: str) -> Variable | None:
        """The variable ``V.<scope>.<name>`` visible in the running frame, or None."""
        if scope == Scope.L:
            return self.frames[-1].local_vars.get(name)
        if scope == Scope.P:
            return self._modal.variables_p.get(name)
        if scope == Scope.G:
            found = self._modal.variables_g.get(name)
            return found if found is not None or "." not in name else self._provided(name)
        for frame in reversed(self.frames):
            found = frame.cycle_vars.get(name)
            if found is not None:
                return found
        return None

    def _provided(self, name: str) -> Variable | None:
        """The V.G. variables the decoder provides: ``HSCS.<MODE>.TOLERANCE`` (mm),
        ``WZ_AKT.R`` (radius of the active tool, mm) and ``NP.V.<axis>`` / ``NP.V``
        (the zero offset table, mm: ``NP[j].V.X``, ``NP[j].V[i]``). A fresh copy each
        time: a write of ``NP`` goes to ``write_zero_offset``."""
        if name.startswith("NP.V"):
            return self._zero_offsets(name)
        if name == "WZ_AKT.R":
            value = self.executor.tool_radius(self._modal.tool_offset) or 0.0
        else:
            parts = name.split(".")
            if len(parts) != 3 or parts[0] != "HSCS" or parts[2] != "TOLERANCE" \
                    or parts[1] not in HSCS_MODES:
                return None
            setting = self.surroundings.hscs.get(parts[1])
            value = setting.tolerance_mm if setting is not None else 0.0
        return Variable(f"V.G.{name}", VarType.REAL64, (), [float(value)])

    def _zero_offsets(self, name: str) -> Variable | None:
        """``NP.V.<axis>``: the offsets of one axis per group (index j = G159 j: 1 is
        G54 .. 6 is G59, 0 is G53), or ``NP.V``: groups x axes; mm, from the live table
        the objects show."""
        table = self._modal.tooling.zero_offsets
        axes = tuple(self.axes)
        groups = table.groups
        if name == "NP.V":
            values: list[Value] = [table.offset_mm(g, k) for g in range(groups)
                                   for k in range(len(axes))]
            return Variable(f"V.G.{name}", VarType.REAL64, (groups, len(axes)), values)
        axis = name[len("NP.V."):]
        if axis not in axes:
            return None
        k = axes.index(axis)
        return Variable(f"V.G.{name}", VarType.REAL64, (groups,),
                        [table.offset_mm(g, k) for g in range(groups)])

    def write_zero_offset(self, variable: Variable, indices: tuple[int, ...], value: Value,
                          line: LogicalLine, pos: int) -> None:
        """``V.G.NP[j].V.<axis> = value`` / ``V.G.NP[j].V[i] = value`` (mm): from here on
        in this run's decoding, in the channel's table when the next block is
        interpolated (``zero_offset_writes``)."""
        write_zero_offset(self._modal, tuple(self.axes), variable, indices, value, line, pos)

    def cycle_parameter(self, number: int, line: LogicalLine, pos: int) -> Value:
        """``@P<number>`` in the innermost running cycle."""
        for frame in reversed(self.frames):
            params = frame.cycle_params
            if params is not None:
                if number in params:
                    return params[number]
                raise line.error(NcErrorId.CYCLE_PARAMETER_UNDEFINED,
                                 f"@P{number} was not given in the call of this cycle "
                                 f"({frame.program.name})", pos)
        raise line.error(NcErrorId.CYCLE_PARAMETER_UNDEFINED,
                         f"@P{number} outside a cycle: cycle parameters exist only in a cycle "
                         "called with L CYCLE [...]", pos)

    def push_cycle(self, frame: CallFrame, params: dict[int, Value] | None) -> None:
        """Run ``frame`` as a cycle: with its parameters, returning the caller's modal
        G functions (G0..G3, G90/G91, G17..G19) when it ends."""
        if len(self.frames) > MAX_CALL_DEPTH:
            raise NcError(NcErrorId.CALL_DEPTH_EXCEEDED, frame.program.name, 1, 1,
                          f"subprogram calls nested deeper than {MAX_CALL_DEPTH}")
        modal = self._modal
        frame.cycle_params = params if params is not None else {}
        frame.restore = (modal.motion, modal.distance, modal.plane)
        self.frames.append(frame)

    def _return(self) -> None:
        """End the running frame (M17/M29, end of a %L section)."""
        frame = self.frames.pop()
        if frame.restore is not None:
            self._modal.motion, self._modal.distance, self._modal.plane = frame.restore

    def load(self, name: str) -> Program:
        """File ``name`` of the program store, prepared (cached); KeyError when missing,
        OSError/ValueError when unreadable."""
        program = self._files.get(name)
        if program is None:
            text = self._loader(name)
            program = Program(text, name, self.parser, self._skip_levels, self.check)
            self._files[name] = program
        return program

    def has_file(self, name: str) -> bool:
        """True when the program store has file ``name``."""
        try:
            self.load(name)
        except (KeyError, OSError, ValueError):
            return False
        return True

    def declare_block(self, frame: CallFrame, stmt: Control, after: int) -> None:
        """Run the ``#VAR`` block at ``frame.index``."""
        declarations, next_index = read_block(self, frame, stmt, after)
        for declaration in declarations:
            declare(self, frame, declaration)
        frame.index = next_index

    # ------------------------------------------------------------ the work counter

    def look(self, idle_steps: int) -> None:
        """The decoding loop's look at the run, every ``LOOK_EVERY_STEPS`` steps
        (``work_guard``): ``DecodingCancelled`` after a RESET; ENDLESS_LOOP once
        ``idle_steps`` (steps since the last block) exceed the limit. The syntax check
        reports that error and ends (``finished``): nothing after it would ever run."""
        if self.cancelled():
            raise DecodingCancelled  # RESET: the SDA thread ends now
        if idle_steps <= self.idle_steps_max:
            return
        frame = self.frames[-1]
        program = frame.program
        error = work_guard.endless_program(program.src, program.name, frame.index, self.idle_steps_max)
        if self.check is None:
            raise error
        self.check.report(error, ErrorCategory.RESOURCE)
        self.finished = True

    # ------------------------------------------------------------ the general path

    def slow_step(self, frame: CallFrame) -> Block | None:
        """Decode the logical line at ``frame.index`` with the general parser (or end
        the frame's section); the Block it produces, if any."""
        if self.check is not None:
            return self._checked_step(frame)
        try:
            if frame.index >= frame.section.end:
                self._end_of_section(frame)
                return None
            return self._step(frame)
        except NcError:
            raise
        except RecursionError:
            raise NcError(NcErrorId.EXPRESSION_TOO_COMPLEX, frame.program.name,
                          frame.index + 1, 1, "program too deeply nested to decode") from None
        except Exception as exc:  # a decoder bug must still be the program's error
            raise self.fault(exc, frame, frame.index) from exc

    def fault(self, exc: Exception, frame: CallFrame, index: int) -> NcError:
        """An unexpected exception as the program's error (logged with its traceback)."""
        if isinstance(exc, NcError):
            return exc
        log.error("decoder fault in %s line %d", frame.program.name, index + 1, exc_info=exc)
        return NcError(NcErrorId.INTERNAL_ERROR, frame.program.name, index + 1, 1,
                       f"decoder fault: {exc!r}")

    def _step(self, frame: CallFrame) -> Block | None:
        stmt, after = frame.program.statement(frame.index, frame.section.end)
        if stmt is None:
            frame.index = after
            return None
        if type(stmt) is Instruction:
            made = run_instruction(stmt, self)
            frame.index = after
            return made
        if self._modal.pattern is not None and type(stmt) is not Control:
            raise pattern_error(stmt.line, _first_pos(stmt.line))
        if type(stmt) is not NcBlock:
            if type(stmt) is AxisCommand:
                block = self.executor.exchange(stmt, self)
                frame.index = after
                return block
            if type(stmt) is ContourStatement:
                block = execute_contour(stmt, self)
                frame.index = after
                return block
            return self._control.run(frame, stmt, after)  # a real-time loop marker or None
        here = frame.index
        if self.check is None:
            block, flow, flow_pos = self.executor.execute(stmt, self)
        else:
            block, flow, flow_pos = self._execute_checked(stmt)
        frame.index = after
        if flow == Flow.PROGRAM_END:
            self.finished = True
            return block
        if flow == Flow.SUBPROGRAM_END:
            if frame.kind == CallFrameKind.MAIN:
                raise stmt.line.error(
                    NcErrorId.SUBPROGRAM_END_IN_MAIN,
                    "M17/M29 ends a subprogram; the main program ends with M30", flow_pos,
                )
            self._return()
            return block
        if stmt.call is not None:
            self._call(frame, stmt)
        if stmt.goto is not None:
            self._control.goto(frame, stmt.goto, stmt.line, here)
        return block

    # ------------------------------------------------------------ syntax check

    def _checked_step(self, frame: CallFrame) -> Block | None:
        """``slow_step`` of the syntax check: an error is reported, decoding goes on.

        When the call or ``$GOTO`` of an NC block fails after its words ran, the Block
        of the words is still yielded (the modal state has moved to its end)."""
        check = self.check
        assert check is not None  # slow_step calls it only when a syntax check runs
        program = frame.program
        index = frame.index
        end = frame.section.end
        if index >= end:
            self._end_of_section(frame)
            return None
        block = None
        self._executed = None  # the Block of the line's words, set by _execute_checked
        depth = len(frame.control)
        try:
            block = self._step(frame)
        except CheckAborted:
            raise
        except ErrorReported:  # a statement the check dropped: its error is reported
            stmt, after = program.statement(index, end)
            if frame.index == index:
                frame.index = self._skip_failed(frame, stmt, index, after, depth)
        except RecursionError:
            error = NcError(NcErrorId.EXPRESSION_TOO_COMPLEX, program.name, index + 1, 1,
                            "program too deeply nested to decode")
            check.report(error, ErrorCategory.RESOURCE)
            frame.index = program.statement(index, end)[1]
        except Exception as exc:  # every error is the program's, reported
            block = self._executed
            error = self.fault(exc, frame, index)
            stmt, after = program.statement(index, end)
            line = getattr(stmt, "line", None)
            limit = check.errors_per_block
            if not limit or getattr(line, "errors", 0) < limit:  # else the line is done
                check.report(error, categorize(error, line))
            if frame.index == index:
                frame.index = self._skip_failed(frame, stmt, index, after, depth)
        check.line(program.src, index, program.statement(index, end)[1])
        return block

    def _skip_failed(
        self, frame: CallFrame, stmt: Statement | None, index: int, after: int, depth: int,
    ) -> int:
        """Where to go on after the statement at ``index`` failed: an opening control
        statement skips its block (so its end is no follow-up error), others the line.
        A failing ``$UNTIL`` or ``$ENDFOR`` (``depth``: the open blocks before it) ends
        its loop, so the end of an enclosing block is no follow-up error either."""
        if type(stmt) is Control and stmt.kind in OPENERS:
            try:
                return frame.program.structure(stmt, index, frame.section.end).after
            except NcError:
                return after
        if (type(stmt) is Control and stmt.kind in CLOSER_OF and len(frame.control) == depth
                and frame.control and frame.control[-1].kind == CLOSER_OF[stmt.kind]):
            frame.control.pop()
        return after

    def _execute_checked(self, stmt: NcBlock) -> tuple[Block | None, Flow, int]:
        """``executor.execute`` for the syntax check: after an error the offending word
        is dropped and the block executed again (assignments that ran stay done). When
        the whole line is dropped it raises ``ErrorReported`` (no call, no $GOTO)."""
        check = self.check
        assert check is not None  # _step calls it only in a syntax check
        executor = self.executor
        count = getattr(stmt.line, "errors", 0)  # errors reported when it was parsed
        skipped: set[int] = set()  # items left out in the pass (their errors reported)

        def item_failed(error: NcError, k: int) -> None:
            """An item's own error: reported, the item left out, the pass goes on."""
            nonlocal count
            items = stmt.items
            if not holds_error(stmt.line, items, k, error.pos):
                raise error  # not this item's: the general way below
            check.report(error, categorize(error, stmt.line))
            count += 1
            if check.errors_per_block and count >= check.errors_per_block:
                raise ErrorReported  # the line is dropped, its call and $GOTO too
            item = items[k]
            if type(item) is Word and item.kind == WordKind.FEED:  # F unknown now
                self._modal.feed_mm_min = self._modal.feed_mm_min or CHECK_FEED_MM_MIN
            skipped.add(k)

        while True:
            skipped.clear()
            try:
                block, flow, flow_pos = executor.execute(stmt, self, item_failed)
                if flow == Flow.SUBPROGRAM_END and self.frames[-1].kind == CallFrameKind.MAIN:
                    # M17/M29 in the main program: dropped, the rest of the block used
                    check.report(stmt.line.error(
                        NcErrorId.SUBPROGRAM_END_IN_MAIN,
                        "M17/M29 ends a subprogram; the main program ends with M30", flow_pos,
                    ), ErrorCategory.COMBINATION)
                    count += 1
                    if check.errors_per_block and count >= check.errors_per_block:
                        raise ErrorReported
                    flow, flow_pos = Flow.NONE, -1
                self._executed = block
                return block, flow, flow_pos
            except NcError as error:
                check.report(error, categorize(error, stmt.line))
                count += 1
                if check.errors_per_block and count >= check.errors_per_block:
                    raise ErrorReported from None  # the line is dropped, its call and $GOTO too
                done = executor.items_done
                items = stmt.items
                if error.id == NcErrorId.NO_FEED:  # go on as if F were programmed
                    self._modal.feed_mm_min = CHECK_FEED_MM_MIN
                    drop: int | None = -1
                else:
                    drop = item_at(stmt.line, items, error.pos)
                    if drop is None:  # no single word at fault: the line is dropped
                        raise ErrorReported from None
                    item = items[drop]
                    if type(item) is Word and item.kind == WordKind.FEED:  # F unknown now
                        self._modal.feed_mm_min = self._modal.feed_mm_min or CHECK_FEED_MM_MIN
                kept = [item for k, item in enumerate(items) if k != drop and k not in skipped
                        and not (k < done and type(item) is Assign)]
                stmt = replace(stmt, items=kept)

    # ------------------------------------------------------------ subprograms

    def _call(self, frame: CallFrame, stmt: NcBlock) -> None:
        call = stmt.call
        assert call is not None  # _step calls it only for a block with a call
        line = stmt.line
        if call.cycle is not None:
            call_cycle(self, frame, stmt)
            return
        if len(self.frames) > MAX_CALL_DEPTH:
            raise line.error(
                NcErrorId.CALL_DEPTH_EXCEEDED,
                f"subprogram calls nested deeper than {MAX_CALL_DEPTH}", call.pos,
            )
        if call.local:
            sections = frame.program.local(call.name)
            if not sections:
                raise line.error(
                    NcErrorId.SUBPROGRAM_NOT_FOUND,
                    f"local subprogram {call.name} not found (no %L {call.name} in "
                    f"{frame.program.name})", call.pos,
                )
            if len(sections) > 1:
                raise line.error(
                    NcErrorId.DUPLICATE_SUBPROGRAM,
                    f"%L {call.name} is defined {len(sections)} times", call.pos,
                )
            section = sections[0]
            self.frames.append(CallFrame(frame.program, section, section.start, CallFrameKind.LOCAL))
            return
        try:
            program = self.load(call.name)
        except KeyError:
            raise line.error(
                NcErrorId.FILE_NOT_FOUND, f"file {call.name} not found", call.pos
            ) from None
        except (OSError, ValueError) as exc:
            raise line.error(
                NcErrorId.FILE_NOT_FOUND, f"file {call.name} cannot be read: {exc}", call.pos
            ) from None
        self.frames.append(CallFrame(program, program.main, program.main.start, CallFrameKind.FILE))

    def _end_of_section(self, frame: CallFrame) -> None:
        if self.check is None:
            self._end_section(frame)
            return
        try:
            self._end_section(frame)
        except NcError as error:
            self.check.report(error, categorize(error, None))
            frame.control.clear()
            if error.id == NcErrorId.BLOCK_NOT_CLOSED:
                self._end_of_section(frame)  # the end itself may be an error too
            elif frame.kind == CallFrameKind.MAIN:
                self.finished = True
            else:
                self._return()

    def _end_section(self, frame: CallFrame) -> None:
        pattern = self._modal.pattern
        if pattern is not None and frame.kind == CallFrameKind.MAIN:
            self._modal.pattern = None
            raise pattern.line.error(NcErrorId.PATTERN_NOT_CLOSED,
                                     f"#PATTERN BEGIN [ID={pattern.id}] without #PATTERN END",
                                     pattern.pos)
        if frame.control:
            entry = frame.control[-1]
            closer = next(c for c, o in CLOSER_OF.items() if o == entry.kind)
            raise entry.stmt.line.error(
                NcErrorId.BLOCK_NOT_CLOSED,
                f"{SPELLING[entry.kind]} without {SPELLING[closer]}", entry.stmt.pos,
            )
        if frame.kind == CallFrameKind.LOCAL:  # %L ends at the next % line: implicit M17
            self._return()
            return
        line = _last_code_line(frame.program, frame.section)
        name = frame.program.name
        if frame.kind == CallFrameKind.FILE:
            raise NcError(NcErrorId.SUBPROGRAM_END_MISSING, name, line, 1,
                          f"subprogram {name} ends without M17 or M29")
        if self.manual:
            self.finished = True
            return
        raise NcError(NcErrorId.MISSING_PROGRAM_END, name, line, 1,
                      f"program {name} ends without M30 (or M2)")


def _never() -> bool:
    return False


def _first_pos(line: LogicalLine) -> int:
    """Position of the first non-blank character of ``line``."""
    text = line.text
    return len(text) - len(text.lstrip())


def _last_code_line(program: Program, section: Section) -> int:
    """1-based number of the last line with code in ``section`` (for end errors)."""
    line = program.src.line
    for k in range(section.end - 1, section.start - 1, -1):
        if strip_comments(line(k)).strip():
            return k + 1
    return max(section.start, 1)
