"""Executing one parsed NC block against the modal state: the reference semantics.

(Over 600 lines, on purpose: one NC block's rules, from its words through the modal
groups, tools, zero offsets and motion to its Block, read in the order they apply; the
parts that stand alone are in tool_data, homing_block, technology and geometry.)

Items run left to right (an assignment changes the variables the following words
read). Then, in this order: G functions (at most one per group), D, F, S, T, the
motion (G0..G3, absolute or incremental, arcs by I/J/K or R), G4 dwell, M functions.

G4 (dwell) takes its time in seconds from the ``X`` or the ``F`` word of its block
(``G4 X2`` or ``G4 F2``); the block has no motion and F keeps its modal value.

A ``Block`` is produced when the NC block has a motion, a dwell, a stop, M, S or T;
blocks that only change modal state (``G90``, ``F500``, ``D1``) produce none. A G0/G1
to the current position gives a block without motion.

An axis released by ``#AX RELEASE`` (``exchange``) cannot be programmed: its axis word,
its I/J/K offset or an arc in a plane that needs it is an error; its position stays.
"""

from __future__ import annotations

import math
import operator
from collections.abc import Callable, Mapping, Sequence
from dataclasses import replace
from enum import IntEnum

from cnc_objects.protocol.units import UM01_PER_MM
from cnc_objects.protocol.values import SPINDLE_M_FUNCTIONS

from ..path.kinematics import Kinematics
from .blocks import (
    AxisExchange,
    AxisExchangeKind,
    Block,
    Compensation,
    ManualModeKind,
    Motion,
    MotionKind,
    StopKind,
    TrafoUse,
)
from .construct import make_block, make_motion, make_source
from .coordinates import Placement
from .cycles.rotation import Vector
from .errors import ErrorAt, NcError, NcErrorId
from .evaluation import Env
from .exchange import moved_axes
from .expressions import evaluate_number
from .geometry import centre_from_offsets, centre_from_radius
from .homing_block import HomingStep, homing_steps, with_homing
from .manual_block import manual_mode_request, with_manual_mode
from .modal import G_CODES, PLANE_AXES, DistanceMode, GGroup, MCode, ModalState, Plane
from .orientation_vector import AxisWords, rotary_words
from .statements import Assign, AxisCommand, NcBlock, Word, WordKind
from .tool_data import ToolTable, program_shift_mm
from .variables import VariableFault


class Flow(IntEnum):
    """What a block does to program flow."""

    NONE = 0  # continue with the next line
    PROGRAM_END = 1  # M2/M30: the block is the last one
    SUBPROGRAM_END = 2  # M17/M29: return to the caller


M_ORIENT = 19  # spindle positioning: needs a speed > 0, may go with M3/M4
M_STOP = 5
_SPINDLE_DIRECTION = frozenset({3, 4, M_STOP})  # one of them a block

# flow-control M functions -> (stop of the block, flow)
_M_FLOW: dict[int, tuple[StopKind, Flow]] = {
    MCode.STOP: (StopKind.PROGRAMMED, Flow.NONE),
    MCode.OPTIONAL_STOP: (StopKind.OPTIONAL, Flow.NONE),
    MCode.PROGRAM_END: (StopKind.PROGRAM_END, Flow.PROGRAM_END),
    MCode.PROGRAM_END_RESET: (StopKind.PROGRAM_END, Flow.PROGRAM_END),
    MCode.SUBPROGRAM_END: (StopKind.NONE, Flow.SUBPROGRAM_END),
    MCode.SUBPROGRAM_END_FAST: (StopKind.NONE, Flow.SUBPROGRAM_END),
}

# the syntax check's handler of an error of item <index> of a block: returns to leave
# the item out and go on, raises to end the block
ItemFailed = Callable[[NcError, int], None]

# The largest feed: the path velocity is carried in 0.1 um/s as SGN32 (as the ISG
# interface objects carry it), 2**31 - 1 increments = 12,884,901.88 mm/min.
FEED_MAX_MM_MIN = (2**31 - 1) / UM01_PER_MM * 60.0

# plane -> (p, q, normal) as indices into (X, Y, Z); and the plane of each normal
_CS_PLANE = {Plane.XY: (0, 1, 2), Plane.ZX: (2, 0, 1), Plane.YZ: (1, 2, 0)}
_PLANE_OF_NORMAL = {2: Plane.XY, 1: Plane.ZX, 0: Plane.YZ}
WEIGHTING_MIN_PCT = 1.0  # G133/G134 percent range
WEIGHTING_MAX_PCT = 1000.0
BBTRC_MAX = 1000  # blocks the bottleneck check of an LA_ON section may compare
_OFFSET_LETTER = ("I", "J", "K")
# the plain fields of the ModalState a block may change (variables excluded)
_MODAL_FIELDS = ("position_mm", "distance", "plane", "motion", "feed_mm_min", "compensation",
                 "tool_offset", "spindle_speed_rpm", "tool", "look_ahead_params",
                 "look_ahead_mark", "zero_offset_group", "spindle_tool")
# modal G groups -> the ModalState field they set
_MODAL_FIELD = {
    GGroup.MOTION: "motion", GGroup.PLANE: "plane",
    GGroup.COMPENSATION: "compensation", GGroup.DISTANCE: "distance",
    GGroup.ZERO_OFFSET: "zero_offset_group",
}
G159 = 159  # G159 = <i>: zero offset group i (in the groups of a block)
M_TOOL_CHANGE = 6  # M6: change to the tool T selected



Groups = dict[GGroup, tuple[int, int]]  # G group -> (G number, pos)
Offsets = dict[int, tuple[float, int]]  # channel axis of I/J/K -> (offset, pos)
Words = dict[WordKind, tuple[float, int]]  # F S T D R ... -> (value, pos)
#: (plane axes or None, plane of line motions, roles of I/J/K (0 = p, 1 = q, -1 =
#: outside), getter of the axes outside the plane (one value or a tuple) or None)
ArcSetup = tuple[
    tuple[int, int] | None, tuple[int, int], tuple[int, ...],
    Callable[[Sequence[float]], object] | None,
]


def _integer(value: float) -> int | None:
    """``value`` as a non-negative int, or None when it is not one."""
    if value < 0 or value != int(value) or value > 0xFFFFFFFF:
        return None
    return int(value)


def _h_word(value: float, pos: int, h_codes: dict[int, int], err: ErrorAt) -> None:
    """One H word: ISG rounds its value to an integer; a negative one, or the same H
    number twice in the block (ISG 20766), is an error."""
    number = round(value)
    if value < 0 or number > 0xFFFF:
        raise err(NcErrorId.INVALID_H_CODE,
                  f"H{value:g} is not a valid H function (0..65535)", pos)
    if number in h_codes:
        raise err(NcErrorId.H_FUNCTION_TWICE, f"H{number} programmed twice in one block", pos)
    h_codes[number] = pos


class BlockExecutor:
    """Applies NC blocks to a ``ModalState`` and builds the ``Block`` objects."""

    def __init__(
        self, axes: tuple[str, ...], tools: Mapping[int, float], modal: ModalState,
        manual: bool, axis_numbers: tuple[int, ...] | None = None,
    ) -> None:
        self.axes = axes
        # logical axis number of each channel axis (#AX RELEASE NBR, #AX REQUEST)
        self.axis_numbers = axis_numbers or tuple(range(1, len(axes) + 1))
        self.tools = tools
        self.modal = modal
        # the decoder reads the tool list of the modal state's tables (a channel's live
        # list); a modal state without one takes the radii given here
        if not modal.tooling.tools.checks_tools and not modal.tooling.tools.rows:
            modal.tooling.tools = ToolTable.from_radii(tools)
        self._np_index = 0  # the index of this block's G159 = <i>
        self.manual = manual
        self.items_done = 0  # items of the last block executed before it ended or failed
        # P-CHAN-00041: M numbers with a synchronisation kind (the decoder sets it from
        # its surroundings); None: every M is known
        self.m_function_known: Callable[[int], bool] | None = None
        # the channel's kinematics (``#ORI MODE [VECTOR_2DOF]`` under #TRAFO ON)
        self.kinematic_chain: Kinematics | None = None
        index = {name: k for k, name in enumerate(axes)}
        # channel axis indices of X, Y, Z (the axes #CS transforms; #CS needs all three)
        self.xyz: tuple[int, int, int] = (index.get("X", -1), index.get("Y", -1),
                                          index.get("Z", -1))
        # plane -> (p, q) channel axis indices, or None when the channel lacks an axis
        self.plane_axes: dict[Plane, tuple[int, int] | None] = {}
        self._arc_setup: dict[Plane, ArcSetup] = {}
        offset_axes = tuple(index.get(name, -1) for name in "XYZ")  # axes of I, J, K
        for plane, (p, q) in PLANE_AXES.items():
            both = p in index and q in index
            pq = (index[p], index[q]) if both else None
            self.plane_axes[plane] = pq
            roles = tuple(0 if pq and a == pq[0] else 1 if pq and a == pq[1] else -1
                          for a in offset_axes)
            outside = [k for k in range(len(axes)) if pq is None or k not in pq]
            getter = operator.itemgetter(*outside) if outside else None
            self._arc_setup[plane] = (pq, pq or (0, 1), roles, getter)

    def arc_setup(self, plane: Plane) -> ArcSetup:
        """For the hot path: (plane axes or None, plane of line motions, roles of I/J/K
        (0 = p, 1 = q, -1 = outside), getter of the axes outside the plane or None)."""
        return self._arc_setup[plane]

    def tool_radius(self, d: int) -> float | None:
        """Radius of tool entry D (0.0 for D0), None when not in the table."""
        if d == 0:
            return 0.0
        radius = self.modal.tooling.tools.get(d)
        return None if radius is None else float(radius)

    def program_shift(self) -> tuple[float, ...] | None:
        """What an absolute axis word adds per channel axis (zero offset + tool
        length), or None when nothing."""
        modal = self.modal
        # #TRAFO ON: the tool length acts along the tilted tool, in the kinematics
        d = 0 if modal.settings.trafo else modal.tool_offset
        return program_shift_mm(modal.tooling, modal.zero_offset_group, d,
                                int(modal.plane), self.axes)

    def trafo_use(self) -> TrafoUse:
        """What a block decoded under ``#TRAFO ON`` carries: the tool length of D."""
        modal = self.modal
        d = modal.tool_offset
        return TrafoUse(modal.tooling.tools.length_mm(d) if d else 0.0)

    def execute(self, stmt: NcBlock, env: Env, on_error: ItemFailed | None = None
                ) -> tuple[Block | None, Flow, int]:
        """Run one block: (block or None, flow, position of the flow M word).

        A block with an error leaves the modal state as it was (a manual block after
        it continues from the last good one); its assignments are not undone.

        ``on_error`` (the syntax check): an error of one item (its value, a G of a
        group already given, a second program-flow M, ...) is handed to it with the
        item's index; when it returns, the item is left out and the block goes on,
        in the same pass (executing the block again after each error was quadratic).
        """
        modal = self.modal
        saved = tuple(getattr(modal, name) for name in _MODAL_FIELDS)
        try:
            return self._execute(stmt, env, on_error)
        except Exception:  # an NcError, or ``on_error`` ending the block
            for name, value in zip(_MODAL_FIELDS, saved, strict=True):
                setattr(modal, name, value)
            raise

    def _execute(self, stmt: NcBlock, env: Env, on_error: ItemFailed | None = None
                 ) -> tuple[Block | None, Flow, int]:
        line = stmt.line
        err = line.error
        groups: Groups = {}
        axis_words: AxisWords = []
        offsets: Offsets = {}
        words: Words = {}
        m_codes: list[tuple[int, int, int]] = []  # (M number, pos, item index)
        h_codes: dict[int, int] = {}  # H number -> pos
        self.items_done = 0
        for k, item in enumerate(stmt.items):
            try:
                if type(item) is Assign:
                    item.target.assign(env, item.value(env))
                else:
                    value = evaluate_number(item.value, env, line, item.pos)
                    if item.kind == WordKind.H:
                        _h_word(value, item.pos, h_codes, err)
                    else:
                        self._word(item, value, err, groups, axis_words, offsets, words,
                                   m_codes, k)
            except NcError as error:
                if on_error is None:
                    raise
                on_error(error, k)  # the item is left out, the block goes on
            self.items_done += 1
        self._modal_groups(groups)
        self._technology(words, err)
        homed: tuple[int, ...] = ()
        steps: list[HomingStep] = []  # G74: its homing steps, in the order of their places
        manual_mode = None
        if GGroup.MANUAL_MODE in groups:  # G200/G201/G202: the axis words name the axes
            number, g_pos = groups[GGroup.MANUAL_MODE]
            manual_mode = manual_mode_request(number, axis_words, g_pos, len(self.axes), err)
            axis_words = []
        if GGroup.HOMING in groups:  # G74: the axis words are places in the homing sequence
            dwell_s = 0.0
            steps = homing_steps(self.modal, axis_words, groups[GGroup.HOMING][1],
                                 self.plane_axes.get(self.modal.plane) or (0, 1), err)
            motion, homed = steps[0]
            axis_words = []
        elif GGroup.DWELL in groups:  # G4: X or F is the time, F stays as it was
            dwell_s = self._dwell(groups, axis_words, offsets, words, err)
            motion = None
        else:
            dwell_s = 0.0
            if WordKind.FEED in words:
                self._feed(words[WordKind.FEED], err)
            settings = self.modal.settings
            if settings.ori_vector and settings.trafo and self.kinematic_chain is not None:
                axis_words = rotary_words(self.kinematic_chain, axis_words, self.modal,
                                          self.axes, self.program_shift(), err)
            motion = self._motion(groups, axis_words, offsets, words, err)
        stop = StopKind.NONE
        flow = Flow.NONE
        flow_pos = -1
        m_functions: list[int] = []
        spindle_m: int | None = None  # the block's M3/M4/M5 (one at most; M19 may join)
        seen_m: set[int] = set()  # a set: a 1 MB line of distinct M words stays linear
        for number, pos, k in m_codes:
            twice = self._m_twice(number, seen_m, spindle_m, pos, err)
            if twice is None and number == M_ORIENT and not self.modal.spindle_speed_rpm:
                twice = err(NcErrorId.M19_WITHOUT_SPEED,
                            "M19 needs a spindle speed > 0 (S or REV, in this block or "
                            "before)", pos)
            if twice is not None:
                if on_error is None:
                    raise twice
                on_error(twice, k)  # this M is left out
                continue
            seen_m.add(number)
            if number in _SPINDLE_DIRECTION:
                spindle_m = number
            if number == M_TOOL_CHANGE:
                dwell_s += self._tool_change(pos, err)
            action = _M_FLOW.get(number)
            if action is None:
                known = self.m_function_known
                if known is not None and not known(number):
                    unknown = err(NcErrorId.UNKNOWN_M_FUNCTION,
                                  f"M{number} is not defined: the channel's m_synch "
                                  "(P-CHAN-00041) does not list it", pos)
                    if on_error is None:
                        raise unknown
                    on_error(unknown, k)  # this M is left out
                    continue
                m_functions.append(number)
                continue
            if flow_pos >= 0:
                conflict = err(NcErrorId.CONFLICTING_M_CODES,
                               f"M{number} with another program-flow M", pos)
                if on_error is None:
                    raise conflict
                on_error(conflict, k)  # this M is left out
                continue
            stop, flow = action
            flow_pos = pos
        if manual_mode is not None and manual_mode.kind == ManualModeKind.G200 \
                and stop == StopKind.NONE:
            stop = StopKind.MANUAL  # the program waits in manual mode until START
        spindle = words.get(WordKind.SPINDLE)
        tool = words.get(WordKind.TOOL)
        if (motion is None and dwell_s == 0.0 and stop == StopKind.NONE and not m_functions
                and spindle is None and tool is None and not axis_words and not offsets
                and not homed and not h_codes and manual_mode is None
                and WordKind.SPINDLE_POS not in words):
            return None, flow, flow_pos
        line_no, column = line.locate(_first(line.text))
        block = make_block(
            make_source(line.file, line_no, column, line.offset), stmt.number, motion,
            dwell_s, stop, tuple(m_functions), None if spindle is None else spindle[0],
            None if tool is None else int(tool[0]), self.manual, None, None,
            self.modal.look_ahead_mark,
        )
        if self.modal.settings.trafo:
            block = replace(block, trafo=self.trafo_use())
        if homed:
            block = with_homing(block, steps)
        if h_codes:
            block = replace(block, h_functions=tuple(h_codes))
        if WordKind.SPINDLE_POS in words:  # S.POS: the angle of the block's M19
            angle, pos = words[WordKind.SPINDLE_POS]
            if not math.isfinite(angle):
                raise err(NcErrorId.VALUE_OUT_OF_RANGE, f"S.POS={angle} is not a number", pos)
            block = replace(block, spindle_pos_deg=angle % 360.0)
        if manual_mode is not None:
            block = with_manual_mode(block, manual_mode)
        return block, flow, flow_pos

    def _word(self, item: Word, value: float, err: ErrorAt, groups: Groups,
              axis_words: AxisWords, offsets: Offsets, words: Words,
              m_codes: list[tuple[int, int, int]], index: int) -> None:
        """Collect one word of a block (its value evaluated) for the parts that follow."""
        match item.kind:
            case WordKind.AXIS:
                axis_words.append((item.axis, value, item.pos, item.letter))
            case WordKind.OFFSET:
                if item.axis < 0:
                    raise err(
                        NcErrorId.ARC_OFFSET_OUT_OF_PLANE,
                        f"{item.letter}: the channel has no axis "
                        f"{'XYZ'[_OFFSET_LETTER.index(item.letter)]}", item.pos,
                    )
                offsets[item.axis] = (value, item.pos)
            case WordKind.G:
                self._g_word(value, item.pos, groups, err)
            case WordKind.M:
                number = _integer(value)
                if number is None:
                    raise err(NcErrorId.INVALID_M_CODE,
                              f"M{value:g} is not a valid M function", item.pos)
                m_codes.append((number, item.pos, index))
            case WordKind.WEIGHTING:
                self._weighting(item.letter, value, item.pos, err)
            case WordKind.LOOK_AHEAD:
                self._look_ahead_switch(value != 0.0)
            case WordKind.LOOK_AHEAD_PARAM:
                self._look_ahead_param(item.letter, value, item.pos, err)
            case WordKind.ZERO_OFFSET_INDEX:
                self._zero_offset_index(value, item.pos, groups, err)
            case _:  # F S T D R
                words[item.kind] = (value, item.pos)

    @staticmethod
    def _m_twice(number: int, before: set[int], spindle_m: int | None, pos: int,
                 err: ErrorAt) -> NcError | None:
        """The error of an M function the block has already (20765), or of a second
        spindle M function (20155: ISG's spindle takes one of M3/M4/M5 a block; M19 may
        go with M3 or M4, its direction, never with M5)."""
        if number in before:
            return err(NcErrorId.M_FUNCTION_TWICE, f"M{number} twice in one block", pos)
        if number not in SPINDLE_M_FUNCTIONS:
            return None
        other = spindle_m if number != M_ORIENT else None
        if number == M_ORIENT and spindle_m == M_STOP:
            other = M_STOP
        elif number == M_STOP and M_ORIENT in before:
            other = M_ORIENT
        if other is None:
            return None
        return err(NcErrorId.SPINDLE_M_TWICE,
                   f"M{number} after M{other} in one block: the spindle takes one of M3, "
                   "M4, M5 per block (M19 with M3 or M4, never with M5)", pos)

    def exchange(self, stmt: AxisCommand, env: Env) -> Block | None:
        """Run ``#AX RELEASE`` / ``#AX REQUEST``: the block that hands the axes over, or
        None when no axis changes hands."""
        modal = self.modal
        moved = moved_axes(stmt, env, self.axes, self.axis_numbers, modal.released_axes)
        if not moved:
            return None
        if stmt.kind == AxisExchangeKind.RELEASE:
            modal.released_axes = modal.released_axes.union(moved)
        else:
            modal.released_axes = modal.released_axes.difference(moved)
        line = stmt.line
        line_no, column = line.locate(_first(line.text))
        return make_block(
            make_source(line.file, line_no, column, line.offset), stmt.number, None, 0.0,
            StopKind.NONE, (), None, None, self.manual, AxisExchange(stmt.kind, moved), None,
            modal.look_ahead_mark,
        )

    # ------------------------------------------------------------ parts

    def _g_word(self, value: float, pos: int, groups: Groups, err: ErrorAt) -> None:
        number = _integer(value)
        if number is None or number not in G_CODES:
            raise err(NcErrorId.UNSUPPORTED_G_CODE, f"G{value:g} is not supported", pos)
        group = G_CODES[number][0]
        if group == GGroup.ZERO_OFFSET and group in groups:
            raise err(NcErrorId.ZERO_OFFSETS_TWICE,
                      f"G{number}: one zero offset (G53..G59, G159) per block", pos)
        if group == GGroup.MANUAL_MODE and group in groups:
            raise err(NcErrorId.MANUAL_MODE_TWICE,
                      f"G{groups[group][0]} and G{number}: one of G200/G201/G202 per block", pos)
        if group in groups:
            raise err(NcErrorId.CONFLICTING_G_CODES,
                      f"G{groups[group][0]} and G{number} in one block", pos)
        groups[group] = (number, pos)

    def _weighting(self, letter: str, value: float, pos: int, err: ErrorAt) -> None:
        """G133 = <%> (acceleration) / G134 = <%> (ramp time): shown, see technology."""
        if not WEIGHTING_MIN_PCT <= value <= WEIGHTING_MAX_PCT:
            raise err(NcErrorId.VALUE_OUT_OF_RANGE,
                      f"{letter} = {value:g} is outside {WEIGHTING_MIN_PCT:g}.."
                      f"{WEIGHTING_MAX_PCT:g} %", pos)
        settings = self.modal.settings
        if letter == "G133":
            settings.acc_weight_pct = value
        else:
            settings.ramp_weight_pct = value

    def _look_ahead_switch(self, on: bool) -> None:
        """LA_ON / LA_OFF: the blocks from here on carry the parameters (or nothing)."""
        modal = self.modal
        modal.look_ahead_mark = modal.look_ahead_params if on else None

    def _look_ahead_param(self, name: str, value: float, pos: int, err: ErrorAt) -> None:
        """METB = <s> (> the cycle time), VFBT = <factor> (0 < f <= 1), BBTRC = <blocks>
        (an integer 1..BBTRC_MAX); they apply to the blocks that follow."""
        modal = self.modal
        params = modal.look_ahead_params
        if name == "METB":
            if not (math.isfinite(value) and value > modal.cycle_s):
                raise err(NcErrorId.VALUE_OUT_OF_RANGE,
                          f"METB = {value:g} s must be greater than the cycle time "
                          f"{modal.cycle_s:g} s", pos)
            params = replace(params, metb_s=value)
        elif name == "VFBT":
            if not 0.0 < value <= 1.0:
                raise err(NcErrorId.VALUE_OUT_OF_RANGE,
                          f"VFBT = {value:g} is outside 0 < VFBT <= 1 (a factor above 1 "
                          "would exceed the axes' velocity jumps)", pos)
            params = replace(params, vfbt=value)
        else:
            blocks = _integer(value)
            if blocks is None or not 1 <= blocks <= BBTRC_MAX:
                raise err(NcErrorId.VALUE_OUT_OF_RANGE,
                          f"BBTRC = {value:g} must be a whole number of blocks 1..{BBTRC_MAX}",
                          pos)
            params = replace(params, bbtrc=blocks)
        modal.look_ahead_params = params
        if modal.look_ahead_mark is not None:
            modal.look_ahead_mark = params

    def _zero_offset_index(self, value: float, pos: int,
                           groups: Groups, err: ErrorAt) -> None:
        """G159 = <i>: zero offset group i of the table (0 = G53, 1..6 = G54..G59)."""
        if GGroup.ZERO_OFFSET in groups:
            raise err(NcErrorId.ZERO_OFFSETS_TWICE,
                      "G159: one zero offset (G53..G59, G159) per block", pos)
        index = _integer(value)
        if index is None:
            raise err(NcErrorId.ZERO_OFFSET_INDEX_FORMAT,
                      f"G159 = {value:g}: the zero offset group is a whole number >= 0", pos)
        groups_max = self.modal.tooling.zero_offsets.groups - 1
        if index > groups_max:
            raise err(NcErrorId.ZERO_OFFSET_INDEX_RANGE,
                      f"G159 = {index}: the zero offset table has the groups 0..{groups_max}",
                      pos)
        self._np_index = index
        groups[GGroup.ZERO_OFFSET] = (G159, pos)

    def _tool_change(self, pos: int, err: ErrorAt) -> float:
        """M6: the tool T selected goes into the spindle; the path waits the tool
        change time (returned, s)."""
        modal = self.modal
        if modal.tool is None:
            raise err(NcErrorId.TOOL_CHANGE_WITHOUT_TOOL,
                      "M6 without a tool: program T<number> before (or in) the M6 block",
                      pos)
        modal.spindle_tool = modal.tool
        return modal.tooling.tool_change_time_s

    def _modal_groups(self, groups: Groups) -> None:
        for group, (number, _pos) in groups.items():
            field = _MODAL_FIELD.get(group)
            if number == G159:
                self.modal.zero_offset_group = self._np_index
            elif field is not None:  # G4 (DWELL) changes nothing modal
                setattr(self.modal, field, G_CODES[number][1])

    def _technology(self, words: Words, err: ErrorAt) -> None:
        modal = self.modal
        if WordKind.TOOL_OFFSET in words:
            value, pos = words[WordKind.TOOL_OFFSET]
            d = _integer(value)
            if d is None or self.tool_radius(d) is None:
                raise err(NcErrorId.TOOL_NOT_IN_TABLE,
                          f"tool D{value:g} is not in the tool table", pos)
            modal.tool_offset = d
        if WordKind.SPINDLE_REV in words:  # REV of S[...]: the S word
            value, pos = words.pop(WordKind.SPINDLE_REV)
            if value < 0:
                raise err(NcErrorId.NEGATIVE_SPINDLE_REV,
                          f"spindle speed REV{value:g} in S[...] is negative", pos)
            words[WordKind.SPINDLE] = (value, pos)
        if WordKind.SPINDLE in words:
            value, pos = words[WordKind.SPINDLE]
            if value < 0:
                raise err(NcErrorId.INVALID_SPINDLE_SPEED,
                          f"spindle speed S{value:g} is negative", pos)
            modal.spindle_speed_rpm = value
        if WordKind.TOOL in words:
            value, pos = words[WordKind.TOOL]
            t = _integer(value)
            if t is None:
                raise err(NcErrorId.INVALID_TOOL_NUMBER,
                          f"T{value:g} is not a valid tool number", pos)
            if not modal.tooling.tools.knows_tool(t):
                raise err(NcErrorId.UNKNOWN_TOOL,
                          f"T{t}: unknown tool id (no valid entry wz[{t}] in the tool list)",
                          pos)
            modal.tool = t

    def _feed(self, word: tuple[float, int], err: ErrorAt) -> None:
        value, pos = word
        if value <= 0:
            raise err(NcErrorId.INVALID_FEED, f"feed F{value:g} must be greater than 0", pos)
        if value > FEED_MAX_MM_MIN:
            raise err(NcErrorId.VALUE_OUT_OF_RANGE,
                      f"feed F{value:.17g} overflows: at most {FEED_MAX_MM_MIN:,.2f} mm/min", pos)
        self.modal.feed_mm_min = value

    def _dwell(
        self, groups: Groups, axis_words: AxisWords, offsets: Offsets, words: Words,
        err: ErrorAt,
    ) -> float:
        g_pos = groups[GGroup.DWELL][1]
        times = [(v, pos) for axis, v, pos, letter in axis_words if letter == "X"]
        others = [pos for axis, v, pos, letter in axis_words if letter != "X"]
        if WordKind.FEED in words:
            times.append(words[WordKind.FEED])
        if others or offsets or WordKind.RADIUS in words:
            pos = min(others + [p for _, p in offsets.values()]
                      + ([words[WordKind.RADIUS][1]] if WordKind.RADIUS in words else []))
            raise err(NcErrorId.INVALID_DWELL, "a G4 block cannot move axes", pos)
        if not times:
            raise err(NcErrorId.INVALID_DWELL,
                      "G4 needs the dwell time in seconds: G4 X.. or G4 F..", g_pos)
        if len(times) > 1:
            raise err(NcErrorId.INVALID_DWELL, "G4 takes the time from X or F, not both",
                      times[1][1])
        value, pos = times[0]
        if value < 0:
            raise err(NcErrorId.INVALID_DWELL, f"dwell time {value:g} s is negative", pos)
        return value

    def _motion(
        self, groups: Groups, axis_words: AxisWords, offsets: Offsets, words: Words,
        err: ErrorAt,
    ) -> Motion | None:
        modal = self.modal
        radius_word = words.get(WordKind.RADIUS)
        if not axis_words and not offsets and radius_word is None:
            return None
        released = modal.released_axes
        if released:
            self._no_released_axis(released, axis_words, offsets, err)
        kind = modal.motion
        positions = [pos for _, _, pos, _ in axis_words] + [pos for _, pos in offsets.values()]
        if radius_word is not None:
            positions.append(radius_word[1])
        if GGroup.MOTION in groups:
            positions.append(groups[GGroup.MOTION][1])
        motion_pos = min(positions)
        start = modal.position_mm
        end = list(start)
        incremental = modal.distance == DistanceMode.INCREMENTAL
        placement = modal.cs_placement
        shift = None if incremental else self.program_shift()
        if shift is not None and placement is not None:  # #CS lies on the zero offset
            placement = shifted_placement(placement, shift, self.xyz)
        cs_axes = self.xyz if placement is not None else ()
        for axis, value, pos, letter in axis_words:
            if axis < 0:
                raise err(NcErrorId.UNKNOWN_WORD, f"{letter} is not an axis of this channel", pos)
            if axis not in cs_axes:
                end[axis] = (start[axis] + value if incremental
                             else value + shift[axis] if shift is not None else value)
        if placement is not None:  # X, Y, Z are programmed in the machining coordinates
            cs_start, cs_end = self._cs_targets(placement, start, end, axis_words, incremental)
        for axis, _value, pos, letter in axis_words:
            if not math.isfinite(end[axis]):
                raise err(NcErrorId.VALUE_OUT_OF_RANGE, f"{letter} position is out of range", pos)
        end_t = tuple(end)
        arc = kind == MotionKind.ARC_CW or kind == MotionKind.ARC_CCW
        if not arc and (offsets or radius_word is not None):
            pos = min([p for _, p in offsets.values()]
                      + ([radius_word[1]] if radius_word is not None else []))
            raise err(NcErrorId.ARC_WORDS_WITHOUT_ARC, "I/J/K/R need G2 or G3", pos)
        if kind == MotionKind.RAPID:
            feed = math.inf
        else:
            if modal.feed_mm_min is None:
                raise err(NcErrorId.NO_FEED,
                          f"no feed programmed for G{int(kind)}: program F", motion_pos)
            feed = modal.feed_mm_min / 60.0
        modal.position_mm = end_t
        comp = modal.compensation
        radius = self.tool_radius(modal.tool_offset) or 0.0
        plane_default = self.plane_axes.get(modal.plane) or (0, 1)
        if not arc:
            if end_t == start:
                return None
            return make_motion(kind, start, end_t, feed, plane_default, None, comp, radius)
        if placement is not None:
            return self._arc_in_cs(kind, placement, cs_start, cs_end, start, end_t, offsets,
                                   radius_word, motion_pos, feed, comp, radius, err)
        plane = self.plane_axes[modal.plane]
        if plane is None:
            p_name, q_name = PLANE_AXES[modal.plane]
            raise err(NcErrorId.PLANE_AXIS_MISSING,
                      f"G{int(modal.plane)} needs the axes {p_name} and {q_name}", motion_pos)
        p, q = plane
        if p in released or q in released:
            raise err(NcErrorId.AXIS_RELEASED,
                      f"axis {self.axes[p if p in released else q]} is not in the channel "
                      f"(released by #AX RELEASE): G{int(kind)} in G{int(modal.plane)} needs it",
                      motion_pos)
        # axes outside the plane (Z in G17, ...) move linearly with the angle: a helix
        # (issue 39; ISG "Simple helical interpolation", docs/kernel.md)
        for axis, (_value, pos) in offsets.items():
            if axis != p and axis != q:
                letter = _OFFSET_LETTER["XYZ".index(self.axes[axis])]
                raise err(NcErrorId.ARC_OFFSET_OUT_OF_PLANE,
                          f"{letter} is not in the G{int(modal.plane)} plane", pos)
        try:
            if radius_word is not None:
                if offsets:
                    raise err(NcErrorId.ARC_CENTRE_AND_RADIUS,
                              "program the arc centre (I/J/K) or the radius (R), not both",
                              radius_word[1])
                centre = centre_from_radius(start[p], start[q], end[p], end[q], radius_word[0],
                                            kind == MotionKind.ARC_CCW)
            elif offsets:
                oi = offsets[p][0] if p in offsets else 0.0
                oj = offsets[q][0] if q in offsets else 0.0
                centre = centre_from_offsets(start[p], start[q], end[p], end[q], oi, oj)
            else:
                raise err(NcErrorId.MISSING_VALUE,
                          f"G{int(kind)} needs the centre (I/J/K) or the radius (R)", motion_pos)
        except VariableFault as f:
            raise err(f.err_id, f.message, motion_pos) from None
        return make_motion(kind, start, end_t, feed, plane, centre, comp, radius)


    # ------------------------------------------------------------ machining coordinates

    def _cs_targets(
        self, placement: Placement, start: tuple[float, ...], end: list[float],
        axis_words: AxisWords, incremental: bool,
    ) -> tuple[Vector, Vector]:
        """Set X, Y, Z of ``end`` from words in machining coordinates: (start, end) in
        machining coordinates. Unprogrammed coordinates keep their machining value; when
        none changes, the machine position stays exactly (no rounding motion)."""
        ix, iy, iz = self.xyz
        cs_start = placement.from_machine((start[ix], start[iy], start[iz]))
        programmed = list(cs_start)
        for axis, value, _pos, _letter in axis_words:
            if axis in self.xyz:
                k = self.xyz.index(axis)
                programmed[k] = cs_start[k] + value if incremental else value
        cs_end = (programmed[0], programmed[1], programmed[2])
        if cs_end != cs_start:
            end[ix], end[iy], end[iz] = placement.to_machine(cs_end)
        return cs_start, cs_end

    def _arc_in_cs(
        self, kind: MotionKind, placement: Placement, cs_start: Vector, cs_end: Vector,
        start: tuple[float, ...], end_t: tuple[float, ...], offsets: Offsets,
        radius_word: tuple[float, int] | None, motion_pos: int, feed: float,
        comp: Compensation, radius: float, err: ErrorAt,
    ) -> Motion:
        """G2/G3 in a machining coordinate system: the centre is found in machining
        coordinates, then the arc is placed in the machine plane its plane maps to."""
        modal = self.modal
        p, q, n = _CS_PLANE[modal.plane]
        if cs_end[n] != cs_start[n]:
            raise err(NcErrorId.HELIX_NOT_SUPPORTED,
                      f"{'XYZ'[n]} is outside the G{int(modal.plane)} plane: helical arcs in a "
                      "machining coordinate system (#CS) are not supported", motion_pos)
        column = tuple(row[n] for row in placement.rotation)  # the plane normal on the machine
        m = max(range(3), key=lambda k: abs(column[k]))
        if abs(abs(column[m]) - 1.0) > 1e-12:
            raise err(NcErrorId.ARC_PLANE_TILTED,
                      f"G{int(kind)} in a machining coordinate system whose G{int(modal.plane)} "
                      "plane is tilted against the machine's planes: arcs run in the machine "
                      "planes only (program the arc as straight lines)", motion_pos)
        cs_offsets = {}
        for axis, (value, pos) in offsets.items():
            k = self.xyz.index(axis)
            if k == n:
                raise err(NcErrorId.ARC_OFFSET_OUT_OF_PLANE,
                          f"{_OFFSET_LETTER[k]} is not in the G{int(modal.plane)} plane", pos)
            cs_offsets[k] = value
        try:
            if radius_word is not None:
                if offsets:
                    raise err(NcErrorId.ARC_CENTRE_AND_RADIUS,
                              "program the arc centre (I/J/K) or the radius (R), not both",
                              radius_word[1])
                cp, cq = centre_from_radius(cs_start[p], cs_start[q], cs_end[p], cs_end[q],
                                            radius_word[0], kind == MotionKind.ARC_CCW)
            elif offsets:
                cp, cq = centre_from_offsets(cs_start[p], cs_start[q], cs_end[p], cs_end[q],
                                             cs_offsets.get(p, 0.0), cs_offsets.get(q, 0.0))
            else:
                raise err(NcErrorId.MISSING_VALUE,
                          f"G{int(kind)} needs the centre (I/J/K) or the radius (R)", motion_pos)
        except VariableFault as f:
            raise err(f.err_id, f.message, motion_pos) from None
        centre = list(cs_start)
        centre[p] = cp
        centre[q] = cq
        machine_centre = placement.to_machine((centre[0], centre[1], centre[2]))
        machine_plane = _PLANE_OF_NORMAL[m]
        machine_axes = self.plane_axes[machine_plane]
        # a placement exists only when the channel has X, Y and Z (#CS checks it), so
        # every machine plane has its two axes
        assert machine_axes is not None
        mp, mq, _ = _CS_PLANE[machine_plane]
        if column[m] < 0.0:  # the normal turned over: clockwise seen from the machine
            kind = MotionKind.ARC_CCW if kind == MotionKind.ARC_CW else MotionKind.ARC_CW
        return make_motion(kind, start, end_t, feed, machine_axes,
                           (machine_centre[mp], machine_centre[mq]), comp, radius)

    def _no_released_axis(
        self, released: frozenset[int], axis_words: AxisWords, offsets: Offsets,
        err: ErrorAt,
    ) -> None:
        """An error at the leftmost word (axis or I/J/K) of a released axis, if any."""
        hits = [(pos, axis) for axis, _, pos, _ in axis_words if axis in released]
        hits += [(pos, axis) for axis, (_, pos) in offsets.items() if axis in released]
        if hits:
            pos, axis = min(hits)
            raise err(NcErrorId.AXIS_RELEASED, f"axis {self.axes[axis]} is not in the channel "
                      "(released by #AX RELEASE)", pos)


def shifted_placement(placement: Placement, shift: tuple[float, ...],
                      xyz: tuple[int, ...]) -> Placement:
    """``placement`` moved by the X, Y, Z parts of ``shift`` (the #CS chain is selected
    on top of the zero offset and the tool length)."""
    ox, oy, oz = placement.origin_mm
    dx, dy, dz = (shift[k] if k >= 0 else 0.0 for k in xyz)
    return Placement((ox + dx, oy + dy, oz + dz), placement.rotation)


def _first(text: str) -> int:
    stripped = text.lstrip()
    return len(text) - len(stripped) if stripped else 0


__all__ = ["BlockExecutor", "Compensation", "Flow"]
