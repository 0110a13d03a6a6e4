"""Fast construction of the frozen contract objects (SourceRef, Motion, Block).

The decoder builds three frozen slotted dataclasses per motion block. Their generated
``__init__`` sets every field through ``object.__setattr__`` (frozen), which costs more
than parsing the line. Here each object is built as an instance of a mutable twin
class with the same ``__slots__`` (plain attribute stores), then given its real class by
``__class__`` assignment. CPython allows that between classes of identical layout; the
result *is* a ``Block`` (``type(b) is Block``, equal to one built the normal way, frozen
from then on).

``FAST`` tells whether the twins work on this interpreter (checked once at import); if
not, the make_* functions fall back to the ordinary constructors. The environment
variable ``CNC_PLAIN_CONSTRUCTORS=1`` turns the twins off on purpose: the test suite
runs the decoder both ways and compares (tests/service/kernel/nc/test_fast_constructors.py),
so an edit that breaks one of the two paths fails.
"""

from __future__ import annotations

import os
from typing import Any, cast

from .blocks import (
    AxisExchange,
    Block,
    Compensation,
    ContourCommand,
    LookAheadMark,
    Motion,
    MotionKind,
    SourceRef,
    StopKind,
)


def _twin(cls: type) -> type:
    """A mutable class with the slots of ``cls``, in the same order."""
    return type(f"_Mutable{cls.__name__}", (), {"__slots__": cls.__dict__["__slots__"]})


SourceRefTwin = _twin(SourceRef)
MotionTwin = _twin(Motion)
BlockTwin = _twin(Block)
new = object.__new__


def _fast_source(file: str, line: int, column: int, offset: int) -> SourceRef:
    # a twin's attributes are its slots, unknown to the type checker: Any until cast
    s: Any = new(SourceRefTwin)
    s.file = file
    s.line = line
    s.column = column
    s.offset = offset
    s.__class__ = SourceRef
    return cast(SourceRef, s)


def _fast_motion(
    kind: MotionKind, start_mm: tuple[float, ...], end_mm: tuple[float, ...],
    feed_mm_s: float, plane: tuple[int, int], center_mm: tuple[float, float] | None,
    compensation: Compensation, tool_radius_mm: float,
) -> Motion:
    m: Any = new(MotionTwin)
    m.kind = kind
    m.start_mm = start_mm
    m.end_mm = end_mm
    m.feed_mm_s = feed_mm_s
    m.plane = plane
    m.center_mm = center_mm
    m.compensation = compensation
    m.tool_radius_mm = tool_radius_mm
    m.__class__ = Motion
    return cast(Motion, m)


def _fast_block(
    source: SourceRef, number: int | None, motion: Motion | None, dwell_s: float,
    stop: StopKind, m_functions: tuple[int, ...], spindle_speed_rpm: float | None,
    tool: int | None, manual: bool, axis_exchange: AxisExchange | None = None,
    contour: ContourCommand | None = None, look_ahead: LookAheadMark | None = None,
) -> Block:
    b: Any = new(BlockTwin)
    b.source = source
    b.number = number
    b.motion = motion
    b.dwell_s = dwell_s
    b.stop = stop
    b.m_functions = m_functions
    b.spindle_speed_rpm = spindle_speed_rpm
    b.tool = tool
    b.manual = manual
    b.axis_exchange = axis_exchange
    b.contour = contour
    b.look_ahead = look_ahead
    b.homing_axes = ()
    b.h_functions = ()
    b.manual_mode = None
    b.spindle_pos_deg = None
    b.trafo = None
    b.trafo_switch = False
    b.then = ()
    b.tooling = None
    b.__class__ = Block
    return cast(Block, b)


def _check() -> bool:
    """True when twin construction gives objects equal to normally built ones."""
    try:
        src = _fast_source("f", 1, 2, 3)
        motion = _fast_motion(
            MotionKind.LINEAR, (0.0,), (1.0,), 1.0, (0, 1), None, Compensation.OFF, 0.0
        )
        block = _fast_block(src, 5, motion, 0.0, StopKind.NONE, (), None, None, False)
    except TypeError:  # __class__ assignment refused: layouts differ on this interpreter
        return False
    expected = Block(
        SourceRef("f", 1, 2, 3), 5,
        Motion(MotionKind.LINEAR, (0.0,), (1.0,), 1.0, (0, 1), None, Compensation.OFF, 0.0),
    )
    return type(block) is Block and block == expected and hash(block) == hash(expected)


#: Set to 1 to build with the ordinary constructors (the reference the twins must equal).
PLAIN_CONSTRUCTORS_ENV = "CNC_PLAIN_CONSTRUCTORS"
FAST = os.environ.get(PLAIN_CONSTRUCTORS_ENV, "") != "1" and _check()
if FAST:
    make_source, make_motion, make_block = _fast_source, _fast_motion, _fast_block
else:  # pragma: no cover - other interpreters
    make_source, make_motion, make_block = SourceRef, Motion, Block
