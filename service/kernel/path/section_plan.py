"""Enhanced look-ahead (LA_ON .. LA_OFF): one velocity plan over a whole section.

The SDA task collects the blocks of a section (the blocks decoded under LA_ON up to
LA_OFF, a block that needs a stop, or the end of the program) and plans them here at
once, as the MTC200 NC compiler does at download. The model is exactly the kernel's
(``planner.py``), with two additions of the section:

* VFBT: the velocity-jump limit of a non-tangential transition into a block of the
  section is multiplied by that block's VFBT (0 < VFBT <= 1);
* block rate: the look-ahead buffer takes new blocks between cycles only, so a block
  of the section never lasts less than ``cycle / (buffer_blocks - 1)``: then the path
  can never pass the whole buffer within one cycle (that is what makes the planned
  exit speeds below safe to use at the buffer's end). Bare blocks (no motion, zero
  length) take a slot but no time: a moving block's time covers the bare blocks next
  to it too (``_slots``), and where bare blocks alone would fill the buffer the plan
  stops.

Geometry is prepared as the GEO task will prepare it (``PathPreparation``, tool radius
compensation included). A section starts only where nothing is held back by the
compensation (G40 before its first block, see ``SectionCollector``), so both
preparations see the same blocks from the same state and produce the same elements.

The backward pass over the section (its end is a stop) gives each block end the
highest speed from which every later constraint of the section can be met by braking:
``LookAheadMark.exit_mm_s``. The GEO look-ahead uses it at its last buffered block
instead of a stop, so the buffer's size no longer limits the speed inside a section.

Blocks are then rewritten, never moved off the contour:

* every feed block's F becomes the highest planned speed in it (the HMI shows the
  planned feed; the planned profile stays below every block's F);
* a single-element block without compensation whose profile accelerates or
  decelerates is split into sub-blocks with their own F: each ramp into pieces of equal
  speed change lasting at least METB, and the cruise in between. Sub-blocks are
  ordinary blocks of the same source line and number (block counter, F on the HMI);
  their end points lie on the original element.

BBTRC: with compensation on, each compensated element is compared with the compensated
elements of the next BBTRC blocks (beyond the neighbour the compensation itself trims
against; moves without compensation are not part of the compensated path); when two of
them cross, the tool would cut the contour between them (a bottleneck), and the section
stops before the first of them with COMP_BOTTLENECK.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

from ..nc.blocks import Block, Compensation, LookAheadMark, Motion, MotionKind
from .errors import PathError, PathErrorId
from .geometry import Arc, Element, Line
from .limits import AxisDynamics, corner_limit_mm_s
from .offsets import circle_circle, line_and_arc, line_circle, plane_point, plane_tangent
from .planner import trapezoid
from .segments import PathPreparation, Segment

SPLIT_MIN_MM = 1e-6  # pieces shorter than this are merged into their neighbour
_SAME_FEED = 1e-9  # relative: neighbouring pieces with this close a feed are one


@dataclass(frozen=True)
class SectionPlan:
    """The blocks of a planned section, in order, and the error that cut it short."""

    blocks: list[Block]
    error: PathError | None = None


@dataclass(slots=True)
class _Element:
    """One prepared segment of the section with its planning values."""

    seg: Segment
    index: int  # index of its block in the section
    cap: float
    corner: float  # junction limit to the next element (inf: none)
    stop: bool
    entry: float = 0.0
    exit: float = 0.0
    v_in: float = 0.0
    v_out: float = 0.0
    peak: float = 0.0


def plan_section(blocks: Sequence[Block], dynamics: Sequence[AxisDynamics], *,
                 buffer_blocks: int, cycle_s: float) -> SectionPlan:
    """Plan ``blocks`` (one section, every one carrying its ``look_ahead`` mark).

    Returns the blocks to hand to the GEO task: planned and split where possible. The
    blocks from a preparation error on, or still held by the compensation at the end,
    are handed over as they were (the GEO task plans them alone and reports the
    error); a bottleneck ends the section before the first block it concerns.
    """
    blocks = list(blocks)
    start = next((b.motion.start_mm for b in blocks if b.motion is not None), None)
    if start is None:  # no motion: nothing to plan
        return SectionPlan(blocks)
    elements, planned = _prepare(blocks, dynamics, start)
    error, planned = _bottleneck(elements, blocks, planned)
    elements = [e for e in elements if e.index < planned]
    rate_caps = _limits(elements, blocks[:planned], buffer_blocks, cycle_s, dynamics)
    _passes(elements)
    out = _rewrite(blocks[:planned], elements, rate_caps)
    out.extend(blocks[planned:] if error is None else [])
    return SectionPlan(out, error)


def _mark(block: Block) -> LookAheadMark:
    """The look-ahead mark of a block of the section (``plan_section``: all have one)."""
    if block.look_ahead is None:
        raise ValueError(f"a block of an LA_ON section without its mark: {block.source}")
    return block.look_ahead


def _motion(block: Block) -> Motion:
    """The motion of a block that has elements (a block without motion has none)."""
    if block.motion is None:
        raise ValueError(f"a planned element of a block without motion: {block.source}")
    return block.motion


def _prepare(blocks: list[Block], dynamics: Sequence[AxisDynamics],
             start: Sequence[float]) -> tuple[list[_Element], int]:
    """Segments of the section, and how many leading blocks are complete (their end
    was released by the compensation, no preparation error before)."""
    prep = PathPreparation(dynamics, start)
    index = {id(b): k for k, b in enumerate(blocks)}
    elements: list[_Element] = []
    ended = 0  # blocks 0..ended-1 have ended
    for block in blocks:
        try:
            items = prep.prepare(block)
        except PathError:  # the GEO task meets it too and reports it there
            break
        for item in items:
            if isinstance(item, Segment):
                k = index[id(item.block)]
                elements.append(_Element(item, k, item.speed_mm_s, math.inf, item.stop))
                if item.events:
                    ended = k + 1
            else:
                ended = index[id(item)] + 1
                if item.needs_stop and elements:
                    elements[-1].stop = True
    return [e for e in elements if e.index < ended], ended


def _limits(elements: list[_Element], blocks: list[Block], buffer_blocks: int,
            cycle_s: float, dynamics: Sequence[AxisDynamics]) -> list[float]:
    """Caps (feed, axes, block rate) and junction limits (velocity jumps x VFBT); the
    block-rate cap of every block."""
    jumps = [d.vel_jump_mm_s for d in dynamics]
    block_mm = [0.0] * len(blocks)
    for e in elements:
        block_mm[e.index] += e.seg.length_mm
    slots, stops, per_cycle = _slots(blocks, block_mm, buffer_blocks)
    rate = per_cycle / cycle_s  # blocks per second the buffer can pass
    rate_caps = [length * rate / n for length, n in zip(block_mm, slots, strict=True)]
    last = {e.index: e for e in elements}
    for k in stops:  # bare blocks alone fill the buffer behind block k: it must stop
        last[k].stop = True
    for e, nxt in zip(elements, [*elements[1:], None], strict=True):
        e.cap = min(e.cap, rate_caps[e.index])
        if nxt is None:
            continue
        corner = corner_limit_mm_s(e.seg.tangent_end, nxt.seg.tangent_start, jumps)
        if corner != math.inf:
            corner *= _mark(blocks[nxt.index]).vfbt
        e.corner = corner
    return rate_caps


def _slots(blocks: list[Block], block_mm: list[float],
           buffer_blocks: int) -> tuple[list[int], list[int], int]:
    """How many blocks the path may pass per cycle, how many of them each moving block
    stands for, and the moving blocks after which the buffer holds nothing to move.

    A bare block (no element: no motion, zero length, trimmed away by the compensation)
    takes a slot of the buffer but no time: a moving block stands for itself and the
    bare blocks on both sides of it, so any ``buffer_blocks - 1`` consecutive blocks
    still last a cycle. With compensation, the last compensated block in the buffer
    is held back (no segment yet) with the bare blocks after it: one slot less per
    cycle, and the block before it stands for those bare blocks too. Where bare (or
    held) blocks alone fill the rest of the buffer behind a moving block, nothing
    behind them can enter before the path has passed it: the path must be able to
    stop at its end."""
    held = any(_compensated(b) for b in blocks)
    per_cycle = max(buffer_blocks - 1 - held, 1)
    moving = [k for k, length in enumerate(block_mm) if length > 0.0]
    slots = [1] * len(blocks)
    stops = []
    bounds = [-1, *moving, len(blocks)]
    for i, k in enumerate(moving, start=1):
        nxt = bounds[i + 1]
        before = k - bounds[i - 1] - 1
        after = nxt - k - 1
        gap = after  # blocks behind k that give the path nothing to move
        if nxt < len(blocks) and _compensated(blocks[nxt]):
            trailing = bounds[i + 2] - nxt - 1  # held with nxt
            after += trailing
            gap += 1 + trailing
        slots[k] = 1 + before + after
        if gap >= buffer_blocks - 1:
            stops.append(k)
    return slots, stops, per_cycle


def _compensated(block: Block) -> bool:
    """The block runs with tool radius compensation (a radius of 0 compensates nothing)."""
    m = block.motion
    return m is not None and m.compensation != Compensation.OFF and m.tool_radius_mm > 0.0


def _passes(elements: list[_Element]) -> None:
    """Backward pass (the section ends with a stop), then forward pass with peaks."""
    sqrt = math.sqrt
    nxt_entry = 0.0
    for j in range(len(elements) - 1, -1, -1):
        e = elements[j]
        if j == len(elements) - 1 or e.stop:
            exit_ = 0.0
        else:
            exit_ = min(e.corner, e.cap, elements[j + 1].cap, nxt_entry)
        e.exit = exit_
        e.entry = nxt_entry = min(e.cap, sqrt(exit_ * exit_ + e.seg.two_acc_len))
    v = 0.0
    for e in elements:
        e.v_in = v
        e.v_out = v = min(e.exit, sqrt(v * v + e.seg.two_acc_len))
        e.peak = trapezoid(e.seg.length_mm, e.seg.acc_mm_s2, e.cap, e.v_in, e.v_out)[0]


@dataclass(slots=True)
class _Piece:
    """A (sub-)element as the GEO task will get it: the part of ``element`` up to
    ``end_mm`` with speed limit ``cap`` (the new F, or the axes' for G0)."""

    element: _Element
    start_mm: float
    end_mm: float
    cap: float
    exit: float = 0.0


def _rewrite(blocks: list[Block], elements: list[_Element],
             rate_caps: list[float]) -> list[Block]:
    """The planned blocks: F = planned peak, sub-blocks where a ramp needs them, each
    with the exit speed of a backward pass over the new F values, its block-rate cap
    and the number of section blocks after it."""
    own: dict[int, list[_Element]] = {}
    for e in elements:
        own.setdefault(e.index, []).append(e)
    feed = {k: max(e.peak for e in es) for k, es in own.items()}
    split = {k for k, es in own.items() if len(es) == 1 and _splittable(blocks[k])}
    pieces: list[_Piece] = []
    for e in elements:
        rapid = _motion(blocks[e.index]).kind == MotionKind.RAPID
        if e.index in split:
            begin = 0.0
            for end, f in _pieces(e, _mark(blocks[e.index]).metb_s):
                pieces.append(_Piece(e, begin, end, min(f, e.cap)))
                begin = end
        else:
            pieces.append(_Piece(e, 0.0, e.seg.length_mm,
                                 e.cap if rapid else min(feed[e.index], e.cap)))
    _exits(pieces)
    out: list[Block] = []
    by_element: dict[int, list[_Piece]] = {}
    for p in pieces:
        by_element.setdefault(id(p.element), []).append(p)
    for k, block in enumerate(blocks):
        es = own.get(k)
        if not es or block.motion is None:
            out.append(block)
            continue
        last = by_element[id(es[-1])][-1]
        exit_ = last.exit if es[-1].seg.events else 0.0
        if k in split:
            out.extend(_split(block, by_element[id(es[0])], exit_, rate_caps[k]))
        else:
            out.append(_with_plan(block, _feed(block.motion, feed[k]), exit_, rate_caps[k]))
    total = len(out)
    return [replace(b, look_ahead=replace(b.look_ahead, blocks_after=total - 1 - n))
            if b.look_ahead is not None else b for n, b in enumerate(out)]


def _exits(pieces: list[_Piece]) -> None:
    """Backward pass over the pieces with their new caps: the exit speed at each end
    (0 at the section's end and at stops)."""
    sqrt = math.sqrt
    nxt_entry = 0.0
    for j in range(len(pieces) - 1, -1, -1):
        p = pieces[j]
        e = p.element
        ends_element = j == len(pieces) - 1 or pieces[j + 1].element is not e
        if j == len(pieces) - 1 or (ends_element and e.stop):
            exit_ = 0.0
        else:
            exit_ = min(p.cap, pieces[j + 1].cap, nxt_entry)
            if ends_element:
                exit_ = min(exit_, e.corner)
        p.exit = exit_
        length = p.end_mm - p.start_mm
        nxt_entry = min(p.cap, sqrt(exit_ * exit_ + 2.0 * e.seg.acc_mm_s2 * length))


def _splittable(block: Block) -> bool:
    """Only a plain feed move is split: nothing else happens at its start or end."""
    m = _motion(block)
    return (m.kind != MotionKind.RAPID and m.compensation == Compensation.OFF
            and block.dwell_s == 0.0 and not block.stop and not block.m_functions
            and block.spindle_speed_rpm is None and block.tool is None
            and block.axis_exchange is None and block.contour is None)


def _feed(motion: Motion, speed_mm_s: float) -> Motion:
    """``motion`` with F = ``speed_mm_s`` (G0 keeps its rapid speed)."""
    if motion.kind == MotionKind.RAPID or not speed_mm_s > 0.0:
        return motion
    return replace(motion, feed_mm_s=min(speed_mm_s, motion.feed_mm_s))


def _with_plan(block: Block, motion: Motion, exit_mm_s: float, max_mm_s: float) -> Block:
    return replace(block, motion=motion, look_ahead=replace(
        _mark(block), exit_mm_s=exit_mm_s, max_mm_s=max_mm_s))


def _pieces(e: _Element, metb_s: float) -> list[tuple[float, float]]:
    """(end distance mm, F mm/s) of the sub-blocks of one element's profile: the
    acceleration and deceleration ramps in pieces of equal speed change lasting at
    least ``metb_s``, the cruise between them; short pieces merge into a neighbour."""
    length, a, peak = e.seg.length_mm, e.seg.acc_mm_s2, e.peak
    up = (peak * peak - e.v_in * e.v_in) / (2.0 * a)
    down = (peak * peak - e.v_out * e.v_out) / (2.0 * a)
    pieces: list[tuple[float, float]] = []
    n_up = int((peak - e.v_in) / (a * metb_s))
    for i in range(1, n_up + 1):  # F = speed reached at the piece's end
        v = e.v_in + (peak - e.v_in) * i / n_up
        pieces.append(((v * v - e.v_in * e.v_in) / (2.0 * a), v))
    pieces.append((max(length - down, up), peak))  # the cruise (may be empty)
    n_down = int((peak - e.v_out) / (a * metb_s))
    for i in range(1, n_down + 1):  # F = speed at the piece's start
        v_start = peak - (peak - e.v_out) * (i - 1) / n_down
        v_end = peak - (peak - e.v_out) * i / n_down
        pieces.append((length - (v_end * v_end - e.v_out * e.v_out) / (2.0 * a), v_start))
    merged: list[tuple[float, float]] = []
    for end, feed in pieces:  # drop empty pieces; join neighbours of the same feed
        end = min(end, length)
        if merged and (end - merged[-1][0] <= SPLIT_MIN_MM
                       or abs(feed - merged[-1][1]) <= _SAME_FEED * feed):
            merged[-1] = (end, max(feed, merged[-1][1]))
        else:
            merged.append((end, feed))
    merged[-1] = (length, merged[-1][1])
    return merged


def _split(block: Block, pieces: list[_Piece], exit_mm_s: float,
           max_mm_s: float) -> list[Block]:
    """``block`` as one sub-block per piece of its element; the last one ends where
    the block ends and carries the block's exit speed."""
    motion = _motion(block)
    if len(pieces) == 1:
        return [_with_plan(block, _feed(motion, pieces[0].cap), exit_mm_s, max_mm_s)]
    element = pieces[0].element.seg.element
    out = []
    start = motion.start_mm
    for p in pieces:
        last = p is pieces[-1]
        end = motion.end_mm if last else _point_at(element, motion, p.end_mm)
        part = replace(_feed(motion, p.cap), start_mm=start, end_mm=end)
        out.append(_with_plan(block, part, exit_mm_s if last else p.exit, max_mm_s))
        start = end
    return out


def _point_at(element: Element, motion: Motion, s_mm: float) -> tuple[float, ...]:
    """The point ``s_mm`` along the block's own element, in the block's axes (axes
    outside an arc's plane stay where the block has them)."""
    point = element.point_at(s_mm)
    if isinstance(element, Arc):
        p, q = motion.plane
        out = list(motion.start_mm)
        out[p], out[q] = point[p], point[q]
        return tuple(out)
    return tuple(point)


# ------------------------------------------------------------------ bottleneck (BBTRC)

def _bottleneck(elements: list[_Element], blocks: list[Block],
                planned: int) -> tuple[PathError | None, int]:
    """Compare each compensated element with the compensated elements of the following
    BBTRC blocks that are not its neighbours; a crossing cuts the section before the
    earlier block. Moves without compensation (G40, or a tool radius of 0) are not
    part of the compensated path: a rapid that crosses it higher up is no bottleneck."""
    for i, e in enumerate(elements):
        motion = _motion(e.seg.block)
        if not _compensated(e.seg.block) or e.index >= planned:
            continue
        reach = e.index + _mark(blocks[e.index]).bbtrc
        for other in elements[i + 2:]:
            if other.index > reach or other.index >= planned:
                break
            if other.index <= e.index + 1:
                continue  # the compensation trims neighbours against each other
            if not _compensated(other.seg.block):
                continue  # not the compensated path (G40 departure, moves after it)
            point = _crossing(e.seg.element, other.seg.element, motion.plane)
            if point is not None:
                later = blocks[other.index]
                where = f"N{later.number}" if later.number is not None else \
                    f"line {later.source.line}"
                return PathError(
                    PathErrorId.COMP_BOTTLENECK,
                    f"bottleneck: the compensated path crosses itself at ({point[0]:.4f}, "
                    f"{point[1]:.4f}) with {where}; the tool radius "
                    f"{motion.tool_radius_mm:g} mm does not fit between them "
                    f"(BBTRC={_mark(blocks[e.index]).bbtrc})", blocks[e.index],
                ), e.index
    return None, planned


def _crossing(first: Element, second: Element,
              plane: tuple[int, int]) -> tuple[float, float] | None:
    """A point where the two elements cross inside both (in the plane), or None."""
    for point in _carrier_points(first, second, plane):
        if _on(first, point, plane) and _on(second, point, plane):
            return point
    return None


def _carrier_points(first: Element, second: Element,
                    plane: tuple[int, int]) -> list[tuple[float, float]]:
    """Intersections of the elements' carrier lines / circles in the plane."""
    if isinstance(first, Line) and isinstance(second, Line):
        p1, p2 = plane_point(first.start_mm, plane), plane_point(second.start_mm, plane)
        d1 = plane_point(first.end_mm, plane)
        d2 = plane_point(second.end_mm, plane)
        u = (d1[0] - p1[0], d1[1] - p1[1])
        w = (d2[0] - p2[0], d2[1] - p2[1])
        cross = u[0] * w[1] - u[1] * w[0]
        if abs(cross) <= 1e-15:
            return []
        t = ((p2[0] - p1[0]) * w[1] - (p2[1] - p1[1]) * w[0]) / cross
        return [(p1[0] + t * u[0], p1[1] + t * u[1])]
    if isinstance(first, Arc) and isinstance(second, Arc):
        return circle_circle(first.center, first.radius_mm, second.center, second.radius_mm)
    line, arc = line_and_arc(first, second)
    return line_circle(plane_point(line.start_mm, plane), plane_tangent(line.direction, plane),
                       arc.center, arc.radius_mm)


_INSIDE_MM = 1e-6  # a crossing this close to an element's end is a touching end point


def _on(element: Element, point: tuple[float, float], plane: tuple[int, int]) -> bool:
    """``point`` lies inside ``element`` (not within _INSIDE_MM of its ends)."""
    if isinstance(element, Line):
        a, b = plane_point(element.start_mm, plane), plane_point(element.end_mm, plane)
        dx, dy = b[0] - a[0], b[1] - a[1]
        length = math.hypot(dx, dy)
        if length <= 2 * _INSIDE_MM:
            return False
        s = ((point[0] - a[0]) * dx + (point[1] - a[1]) * dy) / length
        return _INSIDE_MM < s < length - _INSIDE_MM
    angle = math.atan2(point[1] - element.center[1], point[0] - element.center[0])
    s = element.angle_offset(angle) * element.radius_mm
    return _INSIDE_MM < s < element.length_mm - _INSIDE_MM
