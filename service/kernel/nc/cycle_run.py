"""Running a cycle call: built-in cycles, user cycles and call patterns.

``L CYCLE [NAME=<name> @P<n>=<expr> ...]`` evaluates its parameters in the caller,
then:

* a built-in cycle (``cycles.registry``, case-insensitive name) checks its parameters
  (every problem is an error naming the parameter; a syntax check reports them all),
  runs in Python and may return NC text for its motion part, which runs as the cycle's
  body in a frame named after the cycle;
* any other name is a user cycle: with ``LL CYCLE`` a ``%L`` section of the calling
  file, else a file of the program store (``*.ecy`` or any NC file). It runs like a
  file subprogram (ending with M17) and reads its parameters as ``@P<n>``; reading one
  the call did not give is an error naming it.

A cycle leaves the caller's G0..G3, G90/G91 and G17..G19 as they were (its own moves
do not change the caller's modal motion). Results go to the caller's ``V.CYC.``
variables when the caller declared them.

With ``PATTERN_ID`` (and ``PATTERN_RETRACT``) the cycle runs at every position of the
pattern (``patterns``), through a wrapper program ``SysPosPatternWrapper.ecy`` that
this module writes for the call, as ISG's cycle package does.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..path.kinematics import KinematicsError
from .call_stack import CallFrame, CallFrameKind
from .check import ErrorReported, categorize
from .cycles.rotation import RotationOrder, rotation_from_angles
from .errors import NcError, NcErrorId
from .evaluation import number
from .literals import nc_number
from .patterns import PatternPosition
from .program import Program
from .running_decoder import CallingDecoder
from .source import LogicalLine
from .statements import Call, CycleArgs, NcBlock
from .technology import OutputLimitReached
from .tool_orientation import normal_of, rotary_of, turn_line
from .variables import Scope, Value, VariableFault

PATTERN_WRAPPER = "SysPosPatternWrapper.ecy"


@dataclass(slots=True)
class CycleCall:
    """A cycle call with its parameters evaluated (kept by the pattern wrapper)."""

    call: Call
    params: dict[int, Value]
    line: LogicalLine  # the line of the call
    program: Program  # the calling file (LL CYCLE looks for its %L section there)

    @property
    def args(self) -> CycleArgs:
        """What the call passes (NAME, @P, PATTERN_ID, ...)."""
        args = self.call.cycle
        assert args is not None  # call_cycle makes a CycleCall only of a cycle call
        return args


class CycleContext:
    """What a built-in cycle sees: its parameters (defaults filled in), the decoder's
    state, outputs into the caller's ``V.CYC.`` variables, the file store."""

    def __init__(
        self, decoder: CallingDecoder, cycle_call: CycleCall, params: dict[int, Value],
    ) -> None:
        self.decoder = decoder
        self.modal = decoder.modal
        self.params = params
        self.given = cycle_call.params
        self._call = cycle_call

    def error(self, err_id: NcErrorId, message: str, param: int | None = None) -> NcError:
        """An error at the parameter's ``@P`` in the call (else at its NAME)."""
        return self._call.line.error(err_id, message, _param_pos(self._call, param))

    def set_output(self, name: str, value: Value) -> None:
        """``V.CYC.<name>`` of the caller, when it declared one (else nothing)."""
        variable = self.decoder.find_variable(Scope.CYC, name.upper())
        if variable is not None:
            try:
                variable.set(value)
            except VariableFault as fault:  # declared with a type the result does not fit
                raise self.error(fault.err_id, f"result of {self._call.call.name}: "
                                 f"{fault.message}") from None

    def write_file(self, name: str, text: str) -> None:
        """Replace file ``name`` of the output area (nothing in a syntax check)."""
        if self.decoder.check is None:
            try:
                self.decoder.surroundings.write_file(name, text, True)
            except OutputLimitReached as exc:
                raise self.error(NcErrorId.OUTPUT_LIMIT_REACHED,
                                 f"result file {name}: {exc}") from None
            except (OSError, ValueError) as exc:  # e.g. the service is stopping
                raise self.error(NcErrorId.FILE_WRITE_FAILED,
                                 f"cannot write result file {name}: {exc}") from None


def _param_pos(cycle_call: CycleCall, param: int | None) -> int:
    for p in cycle_call.args.params:
        if p.number == param:
            return p.pos
    return cycle_call.call.pos


def call_cycle(decoder: CallingDecoder, frame: CallFrame, stmt: NcBlock) -> None:
    """Run the cycle call of ``stmt`` (the block's words ran already)."""
    call = stmt.call
    # Decoder._call calls it only for a block whose call is a cycle call
    assert call is not None and call.cycle is not None
    args = call.cycle
    params = {p.number: p.value(decoder) for p in args.params}
    cycle_call = CycleCall(call, params, stmt.line, frame.program)
    if args.pattern_id is None:
        if args.pattern_retract is not None:
            raise stmt.line.error(NcErrorId.CYCLE_PARAMETER_UNKNOWN,
                                  "PATTERN_RETRACT without PATTERN_ID", args.pattern_retract_pos)
        run_cycle(decoder, cycle_call)
        return
    _run_pattern(decoder, cycle_call)


def run_cycle(decoder: CallingDecoder, cycle_call: CycleCall) -> None:
    """Start the cycle of ``cycle_call``: a built-in one runs (and may push its motion
    body), a user cycle's frame is pushed."""
    # Deferred, and no circle (nothing cycles/ imports imports this module): the built-in cycles
    # load numpy (~150 ms), which a service that never calls a cycle need not pay at
    # its start. tests/test_import_graph.py counts this import as an edge all the same.
    from .cycles.registry import BUILTIN_CYCLES, builtin_problems

    call = cycle_call.call
    line = cycle_call.line
    builtin = None if call.local else BUILTIN_CYCLES.get(call.name.upper())
    if builtin is not None:
        problems, params = builtin_problems(builtin, cycle_call.params)
        if problems:
            errors = [line.error(p.err_id, p.message, _param_pos(cycle_call, p.number))
                      for p in problems]
            _raise_all(decoder, errors, line)
        text = builtin.run(CycleContext(decoder, cycle_call, params))
        if text:
            program = Program(text, builtin.name, decoder.parser, 1, decoder.check)
            decoder.push_cycle(CallFrame(program, program.main, program.main.start,
                                     CallFrameKind.FILE), cycle_call.params)
        return
    if call.local:
        sections = cycle_call.program.local(call.name)
        if len(sections) != 1:
            raise line.error(NcErrorId.CYCLE_NOT_FOUND if not sections
                             else NcErrorId.DUPLICATE_SUBPROGRAM,
                             f"cycle {call.name}: {'no' if not sections else 'more than one'} "
                             f"%L {call.name} in {cycle_call.program.name}", call.pos)
        section = sections[0]
        decoder.push_cycle(CallFrame(cycle_call.program, section, section.start, CallFrameKind.LOCAL),
                           cycle_call.params)
        return
    try:
        program = decoder.load(call.name)
    except KeyError:
        raise line.error(NcErrorId.CYCLE_NOT_FOUND,
                         f"cycle {call.name} not found: it is no built-in cycle and no file "
                         "of the program store", call.pos) from None
    decoder.push_cycle(CallFrame(program, program.main, program.main.start, CallFrameKind.FILE),
                       cycle_call.params)


def _raise_all(decoder: CallingDecoder, errors: list[NcError], line: LogicalLine) -> None:
    """The first error; a syntax check reports every one of them."""
    check = decoder.check
    if check is None or len(errors) == 1:
        raise errors[0]
    for error in errors:
        check.report(error, categorize(error, line))
    raise ErrorReported


# ---------------------------------------------------------------- call patterns

def _run_pattern(decoder: CallingDecoder, cycle_call: CycleCall) -> None:
    args = cycle_call.args
    line = cycle_call.line
    assert args.pattern_id is not None  # call_cycle runs a pattern only with PATTERN_ID
    pattern_value = number(args.pattern_id(decoder), line, args.pattern_id_pos, "a pattern ID")
    if args.pattern_retract is None:
        raise line.error(NcErrorId.CYCLE_PARAMETER_MISSING,
                         "PATTERN_RETRACT (the retraction plane in Z) is missing: a cycle "
                         "called with PATTERN_ID needs it", args.pattern_id_pos)
    retract = number(args.pattern_retract(decoder), line, args.pattern_retract_pos,
                     "a Z position for PATTERN_RETRACT")
    positions = decoder.modal.patterns.get(int(pattern_value)) \
        if pattern_value == int(pattern_value) else None
    if positions is None:
        raise line.error(NcErrorId.PATTERN_NOT_DEFINED,
                         f"pattern {pattern_value:g} is not defined (#PATTERN BEGIN [ID="
                         f"{pattern_value:g}] ... #PATTERN END before the call)",
                         args.pattern_id_pos)
    missing = [n for n in "XYZ" if n not in decoder.axes]
    if missing:
        raise line.error(NcErrorId.PATTERN_SYNTAX, "a call pattern needs the axes X, Y and Z",
                         args.pattern_id_pos)
    turns = _tool_turns(positions, decoder, line, args.pattern_id_pos)
    text = pattern_wrapper(positions, retract, turns)
    program = Program(text, PATTERN_WRAPPER, decoder.parser, 1, decoder.check)
    frame = CallFrame(program, program.main, program.main.start, CallFrameKind.FILE)
    frame.pattern_call = cycle_call
    decoder.push_cycle(frame, None)


def _tool_turns(positions: tuple[PatternPosition, ...], decoder: CallingDecoder,
                line: LogicalLine, pos: int) -> list[str] | None:
    """For a pattern with tilted positions (``#AT`` about X or Y, a five-axis channel
    under ``#TRAFO ON``): the rotary axes' line before each position, and the last
    one that turns the tool back as it was; None for a pattern without."""
    if not any(p.tilted for p in positions):
        return None
    chain, modal = decoder.surroundings.kinematic_chain, decoder.modal
    if chain is None or not modal.settings.trafo:
        raise line.error(NcErrorId.PATTERN_ROTATION_NOT_SUPPORTED,
                         "a call pattern with #AT rotations about X or Y turns the tool: "
                         "program #TRAFO ON before the call", pos)
    start = rotary_of(chain, modal)
    near, turns = start, []
    for p in positions:
        rotation = rotation_from_angles(p.a_deg, p.b_deg, p.c_deg, RotationOrder.ZYX, True)
        try:
            turn, near = turn_line(chain, decoder.axes, normal_of(rotation, modal), near)
        except KinematicsError as fault:
            raise line.error(NcErrorId.TRAFO_POSE_UNREACHABLE,
                             f"#AT [{p.x_mm:g}, {p.y_mm:g}, {p.z_mm:g}, {p.a_deg:g}, "
                             f"{p.b_deg:g}, {p.c_deg:g}]: {fault}", pos) from None
        turns.append(turn)
    words = " ".join(f"{decoder.axes[k]}{nc_number(v)}" for k, v in sorted(start.items()))
    turns.append(f"G90 G00 {words}")
    return turns


def pattern_wrapper(positions: tuple[PatternPosition, ...], retract_mm: float,
                    tool_turns: list[str] | None = None) -> str:
    """The NC text that runs a cycle at every position (``#PATTERN CALL`` runs it);
    ``tool_turns`` (``_tool_turns``) turn the tool onto each tilted position's Z axis
    and back at the end; at a tilted position the tool then moves onto that Z axis (in
    the new system), as the retraction plane puts it above an upright one."""
    r = nc_number(retract_mm)
    lines = [f"; call pattern: {len(positions)} positions, retraction plane Z{r}"]
    for k, p in enumerate(positions):
        x, y, z, a, b, c = (nc_number(v) for v in (p.x_mm, p.y_mm, p.z_mm, p.a_deg,
                                                    p.b_deg, p.c_deg))
        lines += [f"G90 G00 Z{r}", f"G00 X{x} Y{y}"]
        if tool_turns is not None:
            lines.append(tool_turns[k])
        lines.append(f"#CS ON [{x}, {y}, {z}, {a}, {b}, {c}]")
        if p.tilted:  # onto the tilted Z axis above the position, as X Y above it
            lines.append("G00 X0 Y0")
        lines += ["#PATTERN CALL", "#CS OFF"]
    lines.append(f"G90 G00 Z{r}")
    if tool_turns is not None:
        lines.append(tool_turns[-1])
    lines.append("M17")
    return "\n".join(lines) + "\n"
