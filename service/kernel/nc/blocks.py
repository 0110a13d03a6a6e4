"""What the decoder hands to path preparation: decoded blocks in absolute coordinates.

This is the contract between the SDA task (``cnc_objects.service.kernel.nc``) and the GEO task
(``cnc_objects.service.kernel.path``). Positions are in mm in the channel's axis order (index 0 is
the channel's first axis); every value is already evaluated (no variables, no
expressions, no incremental coordinates).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from enum import IntEnum


class MotionKind(IntEnum):
    """Interpolation of a motion block (G0..G3)."""

    RAPID = 0  # G0: straight line at the axes' limits (no F)
    LINEAR = 1  # G1
    ARC_CW = 2  # G2: clockwise seen from the positive normal of the plane
    ARC_CCW = 3  # G3


class Compensation(IntEnum):
    """Tool radius compensation in effect for a motion block (G40..G42)."""

    OFF = 40  # G40
    LEFT = 41  # G41: tool left of the contour, seen in the direction of motion
    RIGHT = 42  # G42


class StopKind(IntEnum):
    """Why the path must stop at the end of a block (besides dwell and program end)."""

    NONE = 0  # no stop: the path may run through
    PROGRAMMED = 1  # M0: stop, wait for START
    OPTIONAL = 2  # M1: optional stop; this kernel always stops (no optional-stop switch)
    PROGRAM_END = 3  # M2 / M30: end of the main program
    TECHNOLOGY = 4  # M/S/T functions wait for their acknowledge (kernel.plc_functions)
    MANUAL = 5  # G200: the program waits in manual mode until START ("continue motion")


class ManualModeKind(IntEnum):
    """ISG's manual mode in a program (G200 / G201 / G202)."""

    G200 = 200  # this block: the program stops; the axes jog until START
    G201 = 201  # modal: the axes jog in parallel to the path until G202
    G202 = 202  # modal, initial: manual mode off (for the named axes, or all)


@dataclass(frozen=True, slots=True)
class ManualModeRequest:
    """A G200/G201/G202 block: which axes (channel axis indices) it names."""

    kind: ManualModeKind
    axes: tuple[int, ...]


class AxisExchangeKind(IntEnum):
    """Direction of an axis exchange (#AX RELEASE / #AX REQUEST)."""

    RELEASE = 1  # the axes leave the channel (back to the axis management)
    REQUEST = 2  # the axes (re)join the channel


@dataclass(frozen=True, slots=True)
class SourceRef:
    """Where a block came from: file name, 1-based line and column, byte offset of the line."""

    file: str
    line: int
    column: int = 1
    offset: int = 0


@dataclass(frozen=True, slots=True)
class Motion:
    """A straight line or a circular arc, in absolute mm.

    Arcs lie in the plane of axes ``plane`` = (p, q) (G17: X,Y; G18: Z,X; G19: Y,Z, as
    channel axis indices); ``center_mm`` is the centre in (p, q). Axes outside the plane
    move linearly with the angle (a helix, issue 39). A full circle has ``start_mm`` and
    ``end_mm`` equal in the plane.
    """

    kind: MotionKind
    start_mm: tuple[float, ...]
    end_mm: tuple[float, ...]
    feed_mm_s: float  # programmed path feed F (mm/min / 60); math.inf for G0
    plane: tuple[int, int] = (0, 1)
    center_mm: tuple[float, float] | None = None  # arcs only
    compensation: Compensation = Compensation.OFF
    tool_radius_mm: float = 0.0  # radius of the active D; used when compensation is on


@dataclass(frozen=True, slots=True)
class AxisExchange:
    """#AX RELEASE / #AX REQUEST: channel axis indices (0-based) leaving or (re)joining the
    channel."""

    kind: AxisExchangeKind
    axes: tuple[int, ...]  # channel axis indices, in programmed order, without duplicates


class ContourKind(IntEnum):
    """What a contour look-ahead (FCT-C40) or path-distance command does.

    LOG_ON, LOG_PARAM and LOG_OFF carry the ``block_type`` of their log entry.
    RT_PASS and RT_END are markers the decoder inserts at the passes of a real-time loop
    (``#RT WHILE``) that starts while a marked area is open (see
    ``service/kernel/contour_lookahead.py``); they are not NC blocks of their own.
    """

    LOG_ON = 3  # #CONTOUR LOOKAHEAD LOG ON [PARAM=..]
    LOG_PARAM = 4  # #CONTOUR LOOKAHEAD LOG [PARAM=..]
    LOG_OFF = 5  # #CONTOUR LOOKAHEAD LOG OFF [PARAM=..]
    LOG_CLEAR = 10  # #CONTOUR LOOKAHEAD LOG CLEAR: flush and wait, then empty the log
    DISTANCE_CLEAR = 11  # #DISTANCE PROG START CLEAR: the path distance restarts at 0
    RT_PASS = 12  # marker: pass ``rt_pass`` of real-time loop ``loop`` starts
    RT_END = 13  # marker: real-time loop ``loop`` has ended


class LogArea(IntEnum):
    """The marked area of the contour look-ahead log, as LOG commands move it."""

    NONE = 0  # no LOG ON yet (or since LOG CLEAR)
    OPEN = 1  # after the LOG ON that opened it: elements are logged
    CLOSED = 2  # after its LOG OFF: further LOG ON are ignored until LOG CLEAR


def next_log_area(area: LogArea, kind: ContourKind) -> LogArea:
    """The area after a command of ``kind``: only the first marked area is kept until
    LOG CLEAR; a LOG ON while one is open or closed is ignored."""
    if kind == ContourKind.LOG_ON:
        return LogArea.OPEN if area == LogArea.NONE else area
    if kind == ContourKind.LOG_OFF:
        return LogArea.CLOSED if area == LogArea.OPEN else area
    if kind == ContourKind.LOG_CLEAR:
        return LogArea.NONE
    return area


@dataclass(frozen=True, slots=True)
class ContourCommand:
    """A contour look-ahead or path-distance command, or a real-time loop marker."""

    kind: ContourKind
    param: float | None = None  # PARAM= value as programmed (LOG ON/LOG/LOG OFF)
    loop: int = 0  # RT_PASS/RT_END: serial number of the real-time loop (from 1)
    rt_pass: int = 0  # RT_PASS: number of the pass (from 1)


@dataclass(frozen=True, slots=True)
class LookAheadMark:
    """A block decoded inside ``LA_ON`` .. ``LA_OFF`` (enhanced look-ahead, MTC200).

    The decoder sets the parameters in effect for the block; the section planner of the
    SDA task (``cnc_objects.service.kernel.path.section_plan``) adds what it planned:

    * ``metb_s``: METB, the shortest execution time of a sub-block the planner creates;
    * ``vfbt``: VFBT, factor on the permitted speed of a non-tangential transition
      into this block (0 < VFBT <= 1);
    * ``bbtrc``: BBTRC, how many following blocks the bottleneck check of the tool
      radius compensation compares each compensated block with;
    * ``exit_mm_s``: planned: the highest speed at the end of the block from which every
      later constraint of the section (its end is a stop) can still be met; 0: none;
    * ``max_mm_s``: planned: the block's speed limit from the block rate the look-ahead
      buffer can pass (it holds whatever the feed override);
    * ``blocks_after``: planned: blocks of the section that follow this one (already
      planned, so the GEO task may wait for them without waiting for decoding).
    """

    metb_s: float
    vfbt: float
    bbtrc: int
    exit_mm_s: float = 0.0
    max_mm_s: float = math.inf
    blocks_after: int = 0


@dataclass(frozen=True, slots=True)
class TrafoUse:
    """``#TRAFO ON``: the block's X, Y, Z are the tool tip and its rotary axes the tool's
    orientation; the channel's kinematics turns them into axis positions every cycle,
    with this tool length along the tool."""

    tool_length_mm: float = 0.0


@dataclass(frozen=True, slots=True)
class Block:
    """One decoded NC block: optional motion plus what happens at its end.

    ``number`` is the programmed N number (None when the block has none). A block with
    ``motion`` None, no dwell and no stop is technology only (M/S/T output) and does not
    interrupt the path. A block with ``axis_exchange`` has no motion and stops the
    path: an axis changes hands only at standstill.
    """

    source: SourceRef
    number: int | None = None
    motion: Motion | None = None
    dwell_s: float = 0.0  # G4: wait this long after the block (path speed 0)
    stop: StopKind = StopKind.NONE
    m_functions: tuple[int, ...] = ()  # M words other than the program-flow ones
    spindle_speed_rpm: float | None = None  # S
    tool: int | None = None  # T
    manual: bool = False  # decoded from a manual (MDI) block
    axis_exchange: AxisExchange | None = None  # #AX RELEASE / #AX REQUEST
    contour: ContourCommand | None = None  # #CONTOUR LOOKAHEAD, #DISTANCE, RT loop marker
    look_ahead: LookAheadMark | None = None  # decoded inside LA_ON .. LA_OFF
    homing_axes: tuple[int, ...] = ()  # G74: channel axis indices referenced at its end
    h_functions: tuple[int, ...] = ()  # H words: technology information to the PLC
    manual_mode: ManualModeRequest | None = None  # G200 / G201 / G202
    spindle_pos_deg: float | None = None  # S.POS: where an M19 of the block orients to
    trafo: TrafoUse | None = None  # #TRAFO ON: the positions are tip and orientation
    trafo_switch: bool = False  # #TRAFO ON/OFF: the positions change meaning at standstill
    # G74 with a sequence (G74 Z1 X2): the homing steps after this one, each a block of
    # the same source that starts when the one before has stopped (issue 39)
    then: tuple[Block, ...] = ()
    # what the objects show from this block on (shift, zero offset group, T, D): set by
    # the decoder feed on the first block after a change, None on all others (issue 39)
    # (not compared or hashed: a view of the tables, not part of what the block does)
    tooling: object | None = field(default=None, compare=False)

    @property
    def needs_stop(self) -> bool:
        """True when the path speed must be 0 at the end of this block (LOG CLEAR
        synchronises decoding and execution: flush and wait)."""
        return (self.dwell_s > 0.0 or self.stop != StopKind.NONE
                or self.axis_exchange is not None or bool(self.homing_axes)
                or self.trafo_switch
                or (self.contour is not None and self.contour.kind == ContourKind.LOG_CLEAR))
