"""Decoder errors: one exception type carrying an ISG-style numeric error id and a place.

Every problem the decoder finds in an NC program is an ``NcError`` with the id of the
problem, the file (the subprogram file when the error is inside it), the 1-based line
and column of the offending word or character, and a message a machine operator
understands. The ids live in 20000..22999 like the decoder errors of the ISG kernel.
Ids marked "ISG" are the documented ids of the ISG kernel for the same problem; the
others are this kernel's own and stay stable.

21309 (warning: SYNCHK without MACHINE_LOCK) is ISG's id and raised by the kernel when a
syntax check starts (``cnc_objects.service.kernel.syntax_check``). 22073 (``#CONTOUR
LOOKAHEAD LOG CLEAR`` inside ``#RT WHILE``) is ISG's id and used for that.
"""

from __future__ import annotations

from collections.abc import Callable
from enum import IntEnum


class NcErrorId(IntEnum):
    """Numeric ids of decoder errors."""

    # ---- program selection and faults (also raised by the SDA feed around the decoder)
    PROGRAM_NOT_FOUND = 20000  # the selected program is not in the program store
    INTERNAL_ERROR = 20001  # a decoder fault: a bug, reported as the program's error

    # ---- source text
    COMMENT_BLOCK_NOT_CLOSED = 20101  # #COMMENT BEGIN without #COMMENT END
    COMMENT_END_WITHOUT_BEGIN = 20102  # #COMMENT END without #COMMENT BEGIN
    INVALID_SKIP_LEVEL = 20103  # /n with n outside 1..10
    STRING_NOT_CLOSED = 20104  # "... without the closing quote

    # ---- words of an NC block
    MISSING_VALUE = 20110  # address letter without a value (e.g. "X" alone)
    WORD_REPEATED = 20111  # the same address twice in one block (X1 X2)
    INVALID_BLOCK_NUMBER = 20112  # N not a non-negative integer
    VALUE_OUT_OF_RANGE = 20113  # a number that is not finite or too large for its word (F)
    UNSUPPORTED_G_CODE = 20120  # a G function this decoder does not know
    CONFLICTING_G_CODES = 20121  # two G functions of one group in a block (G0 G1)
    INVALID_M_CODE = 20122  # M not a non-negative integer
    CONFLICTING_M_CODES = 20123  # two program-flow M functions in a block (M0 M30)
    UNKNOWN_M_FUNCTION = 20160  # ISG: an M function P-CHAN-00041 does not define
    INVALID_FEED = 20130  # F <= 0
    NO_FEED = 20008  # ISG "Feed rate in motion block is 0.": G1/G2/G3 without F or prog_start
    INVALID_SPINDLE_SPEED = 20132  # S < 0
    INVALID_TOOL_NUMBER = 20133  # T not a non-negative integer
    TOOL_NOT_IN_TABLE = 20134  # D number without an entry in the tool table
    INVALID_DWELL = 20135  # G4 without a time, negative time, or with axis motion
    INVALID_HOMING = 20136  # G74 without axes
    HOMING_PLACE_OUT_OF_RANGE = 20816  # ISG: G74's value of an axis (its place in the
    # homing sequence) out of range: 0, negative, not a whole number
    TOOL_CHANGE_WITHOUT_TOOL = 20137  # M6 before any T was programmed (project id)
    INVALID_H_CODE = 20138  # H negative or over 65535 (project id: ISG names no id)
    H_FUNCTION_TWICE = 20766  # ISG: the same H function twice in one block
    M_FUNCTION_TWICE = 20765  # ISG: the same M function twice in one block (M8 M8)
    SPINDLE_M_TWICE = 20155  # ISG: a second spindle M function (M3/M4/M5/M19) in a block
    # (M19 may go with M3/M4, its direction; never with M5)
    M19_WITHOUT_SPEED = 20156  # M19 with no spindle speed > 0 set (project id: ISG names none)
    SPINDLE_COMMAND_UNKNOWN = 21035  # ISG: unknown command in the spindle sequence S[...]
    NEGATIVE_SPINDLE_REV = 20991  # ISG: negative spindle speed REV in S[...]
    SPINDLE_POS_TWICE = 20851  # ISG: the spindle position twice (POS or S.POS) in a block
    UNKNOWN_SPINDLE_NAME = 20180  # ISG: S2[...]: a spindle name the channel does not have
    D_IN_SPINDLE_SYNTAX = 21243  # ISG: a D word inside the main spindle's S[...]
    MANUAL_MODE_TWICE = 20129  # ISG: more than one of G200/G201/G202 in one block
    MANUAL_MODE_WITHOUT_AXES = 20139  # G201 without an axis (project id)
    UNKNOWN_TOOL = 21915  # ISG: unknown tool id (T of no valid wz[i] row)
    ZERO_OFFSETS_TWICE = 20116  # ISG: two of G53..G59/G159 in one block
    ZERO_OFFSET_INDEX_RANGE = 20149  # ISG: G159 = <i> beyond the zero offset table
    ZERO_OFFSET_INDEX_FORMAT = 20582  # ISG: G159 = <i> not a whole number >= 0
    BLOCK_NUMBER_TWICE = 20841  # ISG: N programmed twice in one block (N10 N10:)
    UNKNOWN_WORD = 21220  # ISG: unknown or incomplete token (unknown address letter)

    # ---- geometry
    ARC_WORDS_WITHOUT_ARC = 20140  # I/J/K/R in a block that is not G2/G3
    ARC_OFFSET_OUT_OF_PLANE = 20141  # centre offset of an axis outside the plane (K in G17)
    HELIX_NOT_SUPPORTED = 20142  # a helical arc under #CS (plane helices run, issue 39)
    ARC_RADIUS_ZERO = 20143  # centre on the start point
    ARC_RADIUS_TOO_SMALL = 20144  # R smaller than half the chord
    ARC_FULL_CIRCLE_WITH_R = 20145  # R with end point == start point (no unique circle)
    ARC_CENTRE_AND_RADIUS = 20146  # I/J/K and R in the same block
    PLANE_AXIS_MISSING = 20147  # the plane needs an axis the channel does not have
    ARC_PLANE_TILTED = 20148  # G2/G3 in a #CS whose plane maps to no machine plane
    ARC_RADIUS_DIFFERENCE = 21758  # ISG: end point not on the circle (radii differ)

    # ---- axis exchange (#AX RELEASE / #AX REQUEST)
    AXIS_RELEASED = 20150  # a word (X.., I/J/K) or arc plane needs an axis #AX RELEASE released
    AXIS_EXCHANGE_NOT_SUPPORTED = 20151  # #AX REQUEST of a foreign axis, index or name
    AXIS_COMMAND_NOT_ALONE = 20152  # #AX RELEASE/REQUEST with other words in its NC line
    INVALID_AXIS_NUMBER = 20153  # #AX: axis number < 1 or index < 0, or not an integer

    # ---- contour look-ahead (#CONTOUR LOOKAHEAD, #DISTANCE PROG START CLEAR)
    CONTOUR_LOOKAHEAD_NOT_ENABLED = 22070  # #CONTOUR LOOKAHEAD without FCT_CONTOUR_LAH
    CONTOUR_COMMAND_SYNTAX = 22071  # malformed #CONTOUR LOOKAHEAD / #DISTANCE command
    CONTOUR_CLEAR_WITH_COMPENSATION = 22072  # LOG CLEAR while G41/G42 is active
    CONTOUR_CLEAR_IN_RT_LOOP = 22073  # ISG: #CONTOUR LOOKAHEAD LOG CLEAR inside #RT WHILE

    # ---- expressions
    EXPRESSION_SYNTAX = 20200  # malformed expression (missing ']', operator without operand)
    DIVISION_BY_ZERO = 20201  # / or MOD by zero
    MATH_DOMAIN = 20202  # SQRT of a negative number, LN of 0, overflow, ...
    TYPE_MISMATCH = 20203  # a string where a number is needed, or the reverse
    UNKNOWN_FUNCTION = 20204  # NAME[...] that is not a known function
    EXPRESSION_TOO_COMPLEX = 20205  # nesting deeper than the decoder allows

    # ---- variables
    UNDECLARED_VARIABLE = 20300  # use of a variable no #VAR declared
    VARIABLE_DECLARED_TWICE = 20301  # two declarations of one name in one scope
    VARIABLE_SCOPE_NOT_ALLOWED = 20302  # V.P. outside the main program, V.E. ...
    UNKNOWN_TYPE = 20303  # ": TYPE" that is not a known type
    VALUE_OUT_OF_TYPE_RANGE = 20304  # -1 into UNS32, 1e10 into SGN32
    ARRAY_INDEX_OUT_OF_RANGE = 20305  # V.L.A[5] of a 3-element array
    ARRAY_INDEX_MISMATCH = 20306  # index on a scalar, or array used without index
    INVALID_DECLARATION = 20307  # malformed line inside #VAR ... #ENDVAR
    VAR_BLOCK_NOT_CLOSED = 20308  # #VAR without #ENDVAR
    ENDVAR_WITHOUT_VAR = 20309  # #ENDVAR without #VAR
    UNKNOWN_VARIABLE = 20310  # V.E.name: no external variable of that name

    # ---- control flow
    ENDIF_WITHOUT_IF = 20218  # ISG: $ENDIF that matches no $IF
    ELSE_WITHOUT_IF = 20219  # $ELSE / $ELSEIF that matches no $IF
    BLOCK_NOT_CLOSED = 20220  # $IF/$WHILE/$FOR/$SWITCH/$REPEAT/#RT WHILE never closed
    LOOP_END_WITHOUT_BEGIN = 20221  # $ENDWHILE/$ENDFOR/$UNTIL/#RT ENDWHILE without its start
    SWITCH_PART_WITHOUT_SWITCH = 20222  # $CASE/$DEFAULT/$ENDSWITCH outside $SWITCH
    BREAK_OUTSIDE_LOOP = 20223  # $BREAK/$CONTINUE outside a loop or $SWITCH
    FOR_STEP_ZERO = 20224  # $FOR with step 0 would never end
    UNKNOWN_CONTROL_KEYWORD = 20225  # $WORD that is not a control statement
    ENDLESS_LOOP = 20226  # endless program: 1,000,000 steps of work without a block (work_guard)
    LABEL_NOT_FOUND = 20227  # $GOTO to a label the program does not define
    BAD_GOTO_TARGET = 20839  # ISG: character after $GOTO not permitted

    # ---- program structure and subprograms
    MISSING_PROGRAM_END = 20400  # end of a main program without M2/M30
    SUBPROGRAM_END_IN_MAIN = 20401  # M17/M29 in the main program
    SUBPROGRAM_END_MISSING = 20402  # end of a file subprogram without M17/M29
    SUBPROGRAM_NOT_FOUND = 20403  # LL name without %L name in the file
    FILE_NOT_FOUND = 20404  # L name: the program store has no such file
    CALL_DEPTH_EXCEEDED = 20405  # subprogram nesting deeper than MAX_CALL_DEPTH
    DUPLICATE_SUBPROGRAM = 20407  # LL name when the file has two %L sections of that name

    # ---- known but not implemented yet
    INSTRUCTION_NOT_SUPPORTED = 20500  # a #instruction or keyword of a later issue

    # ---- cycles (L CYCLE [...]) and their instructions
    CYCLE_SYNTAX = 20510  # malformed L CYCLE [...] (no NAME, no ']', unknown keyword)
    CYCLE_NOT_FOUND = 20511  # NAME= names no built-in cycle and no file of the store
    CYCLE_PARAMETER_MISSING = 20512  # a required @P parameter was not given
    CYCLE_PARAMETER_UNKNOWN = 20513  # an @P parameter the cycle does not have
    CYCLE_PARAMETER_RANGE = 20514  # an @P value outside its range (or of the wrong type)
    CYCLE_PARAMETER_UNDEFINED = 20515  # @Pn read in a cycle that was called without it
    CYCLE_POINTS_IDENTICAL = 20516  # calculation cycle: the points coincide
    CYCLE_POINTS_COLLINEAR = 20517  # calculation cycle: the points lie on one line
    CYCLE_POINTS_COPLANAR = 20518  # SysCalcSphere: the points lie in one plane
    TRAFO_NOT_CONFIGURED = 20519  # a cycle mode rotates the tool: needs a kinematic trafo
    # the kinematics cannot turn the tool to the direction asked for (ISG: "Kinematic
    # transformation: Illegal argument for ACOS", tf5200_diagnosis/267444363.html)
    TRAFO_POSE_UNREACHABLE = 292004
    # V.G.NP[j] written while G5x selects group j (ISG: "Changing an active zero offset
    # (G54-G59) not permitted", tf5200_diagnosis/1208284683.html)
    ZERO_OFFSET_ACTIVE = 14421
    CYCLE_PARAMETER_TWICE = 20520  # the same @P (or NAME, PATTERN_ID) twice in one call
    PATTERN_NOT_DEFINED = 20521  # PATTERN_ID / #PATTERN DELETE of an undefined pattern
    PATTERN_NESTED = 20522  # #PATTERN BEGIN inside a pattern definition
    PATTERN_COMMAND_INSIDE = 20523  # an ordinary command inside #PATTERN BEGIN ... END
    PATTERN_SYNTAX = 20524  # malformed #PATTERN / #AT, #AT outside a definition
    PATTERN_NOT_CLOSED = 20525  # #PATTERN BEGIN without #PATTERN END
    PATTERN_ROTATION_NOT_SUPPORTED = 20526  # #AT with a rotation about X or Y
    INSTRUCTION_SYNTAX = 20530  # malformed #CS, #FILE, #MSG, #TRAFO, #HSC, #SLOPE, #FILTER
    MESSAGE_FORMAT = 20531  # #MSG: format and arguments do not match
    FILE_WRITE_FAILED = 20532  # #MSG SAVE: the output area refused the write
    OUTPUT_LIMIT_REACHED = 20533  # #MSG SAVE, a cycle's result file: an output_* limit


class NcError(Exception):
    """An error in an NC program, at a place: ``error <id>: <file>:<line>:<column>: <msg>``.

    ``pos`` is the position in the logical line's text when the error was made from one
    (``LogicalLine.error``), else -1: the syntax check repositions by it.
    """

    pos = -1

    def __init__(  # "id" (a builtin's name) is the field name the callers use
        self, id: int, file: str, line: int, column: int, message: str
    ) -> None:
        self.id = id
        self.file = file
        self.line = line
        self.column = column
        self.message = message
        super().__init__(f"error {int(id)}: {file}:{line}:{column}: {message}")

    def __reduce__(  # keep the five fields when pickled
        self,
    ) -> tuple[type[NcError], tuple[int, str, int, int, str]]:
        return (type(self), (self.id, self.file, self.line, self.column, self.message))


class DecodingCancelled(BaseException):
    """Raised inside the decoder when its run was cancelled (RESET) while it works
    without yielding blocks (a loop without motion). A ``BaseException``, so that no
    handler of program errors or decoder faults takes it for one."""


#: ``LogicalLine.error`` of the line being run: (id, message, position) -> the NcError
ErrorAt = Callable[[NcErrorId, str, int], NcError]
