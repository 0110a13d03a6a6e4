"""Running the ``#`` instructions of ``instructions`` against the decoder's state.

None of them moves an axis: they change the modal state (coordinate systems, patterns,
settings) or send a text out (``#MSG``). ``#TRAFO ON/OFF`` on a channel with kinematics
is the one that produces a Block: the positions change meaning, at standstill. ``#MSG SAVE``
writes at decode time, as ISG's decoder does; a syntax check formats it (so a bad
format is reported) but writes nothing.
"""

from __future__ import annotations

from dataclasses import replace

from .blocks import Block, StopKind
from .construct import make_block, make_source
from .coordinates import CoordinateSystem, placement_of
from .cycle_run import run_cycle
from .errors import NcError, NcErrorId
from .evaluation import evaluate_number
from .instructions import Instruction, InstructionKind
from .messages import format_message
from .patterns import OpenPattern, PatternPosition
from .running_decoder import CallingDecoder
from .source import LogicalLine
from .technology import OutputLimitReached
from .variables import VariableFault

DEFAULT_MSG_FILE = "msg_save.txt"  # #MSG SAVE before any #FILE NAME
MAX_PATTERN_POSITIONS = 1000


def run_instruction(stmt: Instruction, decoder: CallingDecoder) -> Block | None:
    """Execute ``stmt`` (raises NcError on a bad value); the block it makes, if any."""
    modal = decoder.modal
    kind = stmt.kind
    if modal.pattern is not None and kind not in (InstructionKind.AT,
                                                  InstructionKind.PATTERN_END):
        if kind == InstructionKind.PATTERN_BEGIN:
            raise stmt.line.error(NcErrorId.PATTERN_NESTED,
                                  "#PATTERN BEGIN inside a pattern definition: close it with "
                                  "#PATTERN END first", stmt.pos)
        raise pattern_error(stmt.line, stmt.pos)
    if kind == InstructionKind.TRAFO:
        return _trafo(stmt, decoder)
    _RUN[kind](stmt, decoder)
    return None


def pattern_error(line: LogicalLine, pos: int) -> NcError:
    """The error for an ordinary command inside ``#PATTERN BEGIN ... END``."""
    return line.error(NcErrorId.PATTERN_COMMAND_INSIDE,
                      "only #AT may stand between #PATTERN BEGIN and #PATTERN END", pos)


def _numbers(stmt: Instruction, decoder: CallingDecoder) -> list[float]:
    return [evaluate_number(v, decoder, stmt.line, p)
            for v, p in zip(stmt.values, stmt.value_pos, strict=True)]


def _integer_id(stmt: Instruction, decoder: CallingDecoder) -> int:
    value = evaluate_number(stmt.values[0], decoder, stmt.line, stmt.value_pos[0])
    if value != int(value) or not 0 <= value <= 0xFFFFFFFF:
        raise stmt.line.error(NcErrorId.PATTERN_SYNTAX,
                              f"pattern ID {value:g} is not a non-negative integer",
                              stmt.value_pos[0])
    return int(value)


# ---------------------------------------------------------------- coordinate systems

def _xyz_present(stmt: Instruction, decoder: CallingDecoder) -> None:
    missing = [n for n in "XYZ" if n not in decoder.axes]
    if missing:
        raise stmt.line.error(NcErrorId.INSTRUCTION_SYNTAX,
                              f"#CS needs the main axes X, Y and Z; the channel has no "
                              f"{', '.join(missing)}", stmt.pos)


def _cs_from_values(stmt: Instruction, decoder: CallingDecoder) -> CoordinateSystem:
    values = _numbers(stmt, decoder)  # 3 or 6 of them (the parser checks the count)
    offset = (values[0], values[1], values[2])
    angles = (values[3], values[4], values[5]) if len(values) == 6 else (0.0, 0.0, 0.0)
    return CoordinateSystem.from_values(offset, angles, stmt.name)


def _select(decoder: CallingDecoder, cs: CoordinateSystem) -> None:
    modal = decoder.modal
    modal.cs = modal.cs + (cs,)
    modal.cs_placement = placement_of(modal.cs)


def _cs_on(stmt: Instruction, decoder: CallingDecoder) -> None:
    _xyz_present(stmt, decoder)
    modal = decoder.modal
    if stmt.values:
        cs = _cs_from_values(stmt, decoder)
        if stmt.name:
            modal.cs_defined[stmt.name] = cs
    else:
        defined = modal.cs_defined.get(stmt.name)
        if defined is None:
            raise stmt.line.error(NcErrorId.INSTRUCTION_SYNTAX,
                                  f"no coordinate system named {stmt.name}: define it with "
                                  f"#CS DEF [{stmt.name}] [x, y, z, a, b, c]", stmt.pos)
        cs = defined
    _select(decoder, cs)


def _cs_def(stmt: Instruction, decoder: CallingDecoder) -> None:
    _xyz_present(stmt, decoder)
    decoder.modal.cs_defined[stmt.name] = _cs_from_values(stmt, decoder)


def _cs_off(stmt: Instruction, decoder: CallingDecoder) -> None:
    modal = decoder.modal
    modal.cs = () if stmt.all else modal.cs[:-1]
    modal.cs_placement = placement_of(modal.cs)


# ---------------------------------------------------------------- patterns

def _pattern_begin(stmt: Instruction, decoder: CallingDecoder) -> None:
    decoder.modal.pattern = OpenPattern(_integer_id(stmt, decoder), stmt.line, stmt.pos)


def _pattern_end(stmt: Instruction, decoder: CallingDecoder) -> None:
    modal = decoder.modal
    pattern = modal.pattern
    if pattern is None:
        raise stmt.line.error(NcErrorId.PATTERN_SYNTAX, "#PATTERN END without #PATTERN BEGIN",
                              stmt.pos)
    modal.pattern = None
    if not pattern.positions:
        raise stmt.line.error(NcErrorId.PATTERN_SYNTAX,
                              f"pattern {pattern.id} has no position: program #AT [x, y, z] "
                              "before #PATTERN END", stmt.pos)
    modal.patterns[pattern.id] = tuple(pattern.positions)


def _pattern_delete(stmt: Instruction, decoder: CallingDecoder) -> None:
    modal = decoder.modal
    if stmt.all:
        modal.patterns.clear()
        return
    number = _integer_id(stmt, decoder)
    if modal.patterns.pop(number, None) is None:
        raise stmt.line.error(NcErrorId.PATTERN_NOT_DEFINED,
                              f"pattern {number} is not defined: only defined patterns can "
                              "be deleted", stmt.value_pos[0])


def _at(stmt: Instruction, decoder: CallingDecoder) -> None:
    pattern = decoder.modal.pattern
    if pattern is None:
        raise stmt.line.error(NcErrorId.PATTERN_SYNTAX,
                              "#AT outside a pattern definition (#PATTERN BEGIN ... END)",
                              stmt.pos)
    values = _numbers(stmt, decoder)
    if len(values) == 6 and decoder.surroundings.kinematic_chain is None:
        # the tool would have to turn with the tilted system: a five-axis channel only
        for k, letter in ((3, "a (about X)"), (4, "b (about Y)")):
            if values[k] != 0.0:
                raise stmt.line.error(NcErrorId.PATTERN_ROTATION_NOT_SUPPORTED,
                                      f"#AT rotation {letter} = {values[k]:g}: on a channel "
                                      "without kinematics only a rotation about Z (the 6th "
                                      "value) is permitted", stmt.value_pos[k])
    if len(pattern.positions) >= MAX_PATTERN_POSITIONS:
        raise stmt.line.error(NcErrorId.PATTERN_SYNTAX,
                              f"a pattern holds at most {MAX_PATTERN_POSITIONS} positions",
                              stmt.pos)
    a, b, c = values[3:6] if len(values) == 6 else (0.0, 0.0, 0.0)
    pattern.positions.append(PatternPosition(values[0], values[1], values[2], c, a, b))


def _pattern_call(stmt: Instruction, decoder: CallingDecoder) -> None:
    cycle_call = decoder.frames[-1].pattern_call
    if cycle_call is None:
        raise stmt.line.error(NcErrorId.PATTERN_SYNTAX,
                              "#PATTERN CALL belongs to the pattern wrapper; call a cycle at a "
                              "pattern with L CYCLE [NAME=.. PATTERN_ID=.. PATTERN_RETRACT=..]",
                              stmt.pos)
    run_cycle(decoder, cycle_call)


# ---------------------------------------------------------------- messages

def _message_text(stmt: Instruction, decoder: CallingDecoder) -> str:
    assert stmt.text is not None  # #MSG and #MSG SAVE: the parser sets the text
    fmt = stmt.text(decoder)
    args = tuple(v(decoder) for v in stmt.values)
    if not isinstance(fmt, str):
        raise stmt.line.error(NcErrorId.TYPE_MISMATCH, "#MSG needs a text in quotes first",
                              stmt.text_pos)
    try:
        return format_message(fmt, args)
    except VariableFault as fault:
        raise stmt.line.error(fault.err_id, fault.message, stmt.text_pos) from None


def _file_name(stmt: Instruction, decoder: CallingDecoder) -> None:
    decoder.modal.msg_file = stmt.name


def _msg(stmt: Instruction, decoder: CallingDecoder) -> None:
    text = _message_text(stmt, decoder)
    if decoder.check is None:
        decoder.surroundings.show_message(text)


def _msg_save(stmt: Instruction, decoder: CallingDecoder) -> None:
    text = _message_text(stmt, decoder)
    if decoder.check is not None:
        return
    name = decoder.modal.msg_file or DEFAULT_MSG_FILE
    # EXCLUSIVE: the first write of this program run replaces the file's content
    replace = stmt.exclusive and name not in decoder.files_written
    decoder.files_written.add(name)
    try:
        decoder.surroundings.write_file(name, text + "\n", replace)
    except OutputLimitReached as exc:
        raise stmt.line.error(NcErrorId.OUTPUT_LIMIT_REACHED,
                              f"#MSG SAVE to {name}: {exc}", stmt.pos) from None
    except (OSError, ValueError) as exc:
        raise stmt.line.error(NcErrorId.FILE_WRITE_FAILED,
                              f"#MSG SAVE cannot write {name}: {exc}", stmt.pos) from None


# ---------------------------------------------------------------- technology

def _tolerance(stmt: Instruction, decoder: CallingDecoder, key: str) -> float:
    node, pos = stmt.options[key]
    assert node is not None  # PATH_DEV, TRACK_DEV, AX_DEV: _options requires their '= value'
    value = evaluate_number(node, decoder, stmt.line, pos)
    if value < 0:
        raise stmt.line.error(NcErrorId.VALUE_OUT_OF_RANGE, f"{key} {value:g} is negative", pos)
    return value


def _trafo(stmt: Instruction, decoder: CallingDecoder) -> Block | None:
    """``#TRAFO ON/OFF``. On a channel with kinematics the decoder's X, Y, Z become the
    tool tip (ON) or the axes again (OFF): its position is turned over with the
    kinematics, and the block returned makes the path turn over its own at standstill.
    On a channel without, the transformation is the identity (a three-axis machine):
    only the setting is shown."""
    settings, modal = decoder.modal.settings, decoder.modal
    chain = decoder.surroundings.kinematic_chain
    if chain is None or stmt.on == settings.trafo:
        settings.trafo = stmt.on
        return None
    use = decoder.executor.trafo_use()
    convert = chain.to_program if stmt.on else chain.to_axes
    modal.position_mm = convert(modal.position_mm, decoder.executor.xyz, use.tool_length_mm)
    settings.trafo = stmt.on
    line_no, column = stmt.line.locate(stmt.pos)
    block = make_block(make_source(stmt.line.file, line_no, column, stmt.line.offset),
                       stmt.number, None, 0.0, StopKind.NONE, (), None, None,
                       decoder.manual, None, None, modal.look_ahead_mark)
    return replace(block, trafo=use if stmt.on else None, trafo_switch=True)


def _ori_mode(stmt: Instruction, decoder: CallingDecoder) -> None:
    """``#ORI MODE [VECTOR_2DOF]``: from now on (to M30), while ``#TRAFO ON``, A B C
    are the components of the tool's direction (``blockexec``); ``[ANGLE]``: the
    rotary axes' angles again (ISG's default)."""
    decoder.modal.settings.ori_vector = stmt.name == "VECTOR_2DOF"


def _hsc(stmt: Instruction, decoder: CallingDecoder) -> None:
    settings = decoder.modal.settings
    settings.hsc = stmt.on
    if not stmt.on:
        return
    settings.hsc_surface = "SURFACE" in stmt.options
    settings.hsc_path_dev_mm = (_tolerance(stmt, decoder, "PATH_DEV")
                                if "PATH_DEV" in stmt.options else 0.0)
    settings.hsc_track_dev_mm = (_tolerance(stmt, decoder, "TRACK_DEV")
                                 if "TRACK_DEV" in stmt.options else 0.0)


def _slope(stmt: Instruction, decoder: CallingDecoder) -> None:
    decoder.modal.settings.slope = stmt.name


def _filter(stmt: Instruction, decoder: CallingDecoder) -> None:
    settings = decoder.modal.settings
    settings.filter = stmt.on
    if stmt.on:
        settings.filter_ax_dev_mm = (_tolerance(stmt, decoder, "AX_DEV")
                                     if "AX_DEV" in stmt.options else 0.0)


_RUN = {
    InstructionKind.CS_ON: _cs_on, InstructionKind.CS_DEF: _cs_def,
    InstructionKind.CS_OFF: _cs_off, InstructionKind.PATTERN_BEGIN: _pattern_begin,
    InstructionKind.PATTERN_END: _pattern_end, InstructionKind.PATTERN_DELETE: _pattern_delete,
    InstructionKind.AT: _at, InstructionKind.PATTERN_CALL: _pattern_call,
    InstructionKind.FILE_NAME: _file_name, InstructionKind.MSG: _msg,
    InstructionKind.MSG_SAVE: _msg_save,
    InstructionKind.HSC: _hsc, InstructionKind.SLOPE: _slope, InstructionKind.FILTER: _filter,
    InstructionKind.ORI_MODE: _ori_mode,
}
