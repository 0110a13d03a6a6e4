"""Modal state of a channel's decoder and the G functions that change it.

``ModalState`` is what a block leaves behind for the next: the programmed position,
G90/G91, the plane, the motion mode, F, tool radius compensation and D, S, T, the
program-global (V.P.) and global (V.G.) variables, the axes released by
``#AX RELEASE``, the machining coordinate systems (``#CS``), call patterns
(``#PATTERN``) and high-speed settings (``#HSC``, ``G133``, ...). It is mutable and
outlives a ``Decoder``: in the extended manual (MDI) mode every new manual block is
decoded with the modal state the previous one left. A program start (a ``Decoder`` that
is not manual) gives all axes back to the channel.

Defaults after a reset: G90, G17, G01 (a motion block without F is an error until an F
is programmed, never an accidental rapid), G40, D0, G53, no F, S or T.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import IntEnum

from .blocks import Compensation, LogArea, LookAheadMark, MotionKind
from .coordinates import CoordinateSystem, Placement
from .patterns import OpenPattern, PatternPosition
from .technology import MachiningSettings
from .tool_data import ToolingTables
from .variables import Variable


class DistanceMode(IntEnum):
    """How axis words are read (G90/G91)."""

    ABSOLUTE = 90  # G90: the word is the target position
    INCREMENTAL = 91  # G91: the word is the distance from the current position


class Plane(IntEnum):
    """Working plane for arcs (G17/G18/G19)."""

    XY = 17  # G17: arcs in X,Y (I, J)
    ZX = 18  # G18: arcs in Z,X (K, I)
    YZ = 19  # G19: arcs in Y,Z (J, K)


# plane -> names of its (p, q) axes; Motion.plane holds their channel axis indices
# METB 10 ms, VFBT 1 (the velocity jumps as configured), BBTRC 8 blocks
DEFAULT_LOOK_AHEAD = LookAheadMark(metb_s=0.010, vfbt=1.0, bbtrc=8)
PLANE_AXES = {Plane.XY: ("X", "Y"), Plane.ZX: ("Z", "X"), Plane.YZ: ("Y", "Z")}


class GGroup(IntEnum):
    """Groups of G functions; one block may hold at most one G of each group."""

    MOTION = 0  # G0 G1 G2 G3 (modal)
    DWELL = 1  # G4 (this block only)
    PLANE = 2  # G17 G18 G19 (modal)
    COMPENSATION = 3  # G40 G41 G42 (modal)
    DISTANCE = 4  # G90 G91 (modal)
    HOMING = 5  # G74 (this block only): homing of the programmed axes
    ZERO_OFFSET = 6  # G53 G54..G59 (modal; G159 = <i> in the same group)
    MANUAL_MODE = 7  # G200 (this block) G201 G202 (modal): manual mode in a program


class ZeroOffsetGroup(IntEnum):
    """The zero offset groups the G functions select (ISG ``np_grp[i]``)."""

    G53 = 0  # no zero offset (initial state)
    G54 = 1
    G55 = 2
    G56 = 3
    G57 = 4
    G58 = 5
    G59 = 6


# the G functions this decoder knows: number -> (group, value set in the modal state)
G_CODES: dict[int, tuple[GGroup, IntEnum | None]] = {
    0: (GGroup.MOTION, MotionKind.RAPID),
    1: (GGroup.MOTION, MotionKind.LINEAR),
    2: (GGroup.MOTION, MotionKind.ARC_CW),
    3: (GGroup.MOTION, MotionKind.ARC_CCW),
    4: (GGroup.DWELL, None),
    17: (GGroup.PLANE, Plane.XY),
    18: (GGroup.PLANE, Plane.ZX),
    19: (GGroup.PLANE, Plane.YZ),
    40: (GGroup.COMPENSATION, Compensation.OFF),
    41: (GGroup.COMPENSATION, Compensation.LEFT),
    42: (GGroup.COMPENSATION, Compensation.RIGHT),
    90: (GGroup.DISTANCE, DistanceMode.ABSOLUTE),
    91: (GGroup.DISTANCE, DistanceMode.INCREMENTAL),
    74: (GGroup.HOMING, None),
    200: (GGroup.MANUAL_MODE, None),
    201: (GGroup.MANUAL_MODE, None),
    202: (GGroup.MANUAL_MODE, None),
    # G53 (no zero offset) and G54..G59: zero offset group np_grp[0..6]
    **{g: (GGroup.ZERO_OFFSET, ZeroOffsetGroup(g - 53)) for g in range(53, 60)},
}


class MCode(IntEnum):
    """M functions that act on program flow (all others go to ``Block.m_functions``)."""

    STOP = 0  # M0: programmed stop
    OPTIONAL_STOP = 1  # M1: optional stop
    PROGRAM_END = 2  # M2: end of program
    SUBPROGRAM_END = 17  # M17: end of subprogram
    SUBPROGRAM_END_FAST = 29  # M29: end of subprogram (ISG: without synchronisation)
    PROGRAM_END_RESET = 30  # M30: end of program with reset


@dataclass(slots=True)
class ModalState:
    """What a decoded block leaves for the next one (mutable, survives a Decoder)."""

    position_mm: tuple[float, ...] = ()  # programmed absolute position per channel axis
    distance: DistanceMode = DistanceMode.ABSOLUTE
    plane: Plane = Plane.XY
    motion: MotionKind = MotionKind.LINEAR
    feed_mm_min: float | None = None  # F; None until programmed
    compensation: Compensation = Compensation.OFF
    tool_offset: int = 0  # D: active tool radius entry (D0 = radius 0)
    spindle_speed_rpm: float | None = None  # last S
    tool: int | None = None  # last T
    variables_p: dict[str, Variable] = field(default_factory=dict)  # V.P. by upper name
    variables_g: dict[str, Variable] = field(default_factory=dict)  # V.G. by upper name
    released_axes: frozenset[int] = frozenset()  # channel axis indices out (#AX RELEASE)
    contour_log_area: LogArea = LogArea.NONE  # marked area of #CONTOUR LOOKAHEAD LOG
    # machining coordinate systems (#CS): the selected chain and its placement (None:
    # none selected, positions are machine positions), and the ones #CS DEF defined
    cs: tuple[CoordinateSystem, ...] = ()
    cs_placement: Placement | None = None
    cs_defined: dict[str, CoordinateSystem] = field(default_factory=dict)
    # call patterns (#PATTERN): the one being defined, and the defined ones by id
    pattern: OpenPattern | None = None
    patterns: dict[int, tuple[PatternPosition, ...]] = field(default_factory=dict)
    settings: MachiningSettings = field(default_factory=MachiningSettings)  # #HSC, G133 ..
    msg_file: str | None = None  # #FILE NAME [MSG=..]: the file of #MSG SAVE
    # enhanced look-ahead (LA_ON/LA_OFF, METB/VFBT/BBTRC): the configured defaults, the
    # values in effect, and the mark blocks get while LA_ON is on (None: LA_OFF)
    look_ahead_defaults: LookAheadMark = DEFAULT_LOOK_AHEAD
    look_ahead_params: LookAheadMark = DEFAULT_LOOK_AHEAD
    look_ahead_mark: LookAheadMark | None = None
    cycle_s: float = 0.001  # GEO cycle time: METB must exceed it
    # G74: channel axis index -> (reference position P-AXIS-00152 in mm, homing speed
    # in mm/s); an axis missing here homes to 0 at HOMING_DEFAULT_MM_S
    homing: dict[int, tuple[float, float]] = field(default_factory=dict)
    # tools and work offsets (tool_data): the channel's live tables, the zero offset
    # group selected (G53..G59, G159) and the tool in the spindle (the T of the last M6)
    tooling: ToolingTables = field(default_factory=ToolingTables)
    zero_offset_group: int = 0
    spindle_tool: int = 0

    def start_program(self) -> None:
        """What a program start resets: no coordinate system, patterns or settings."""
        self.cs = ()
        self.cs_placement = None
        self.cs_defined = {}
        self.pattern = None
        self.patterns = {}
        self.settings = MachiningSettings()
        self.msg_file = None
        self.look_ahead_params = self.look_ahead_defaults
        self.look_ahead_mark = None
        self.zero_offset_group = 0  # G53 is the initial state (P-ZERO-00002 = 0)
