"""The decoding loop, with its hot path for plain motion lines.

Most lines of a CAM program look like ``N120 G1 X12.5 Y-3 Z0.2 F1200 ; comment``. One
regular expression per channel recognises such a line when its words are in the
canonical order ``N G <axes in channel order> I J K F``, with G0..G3 only. For such a
line the loop applies the modal state directly and builds the Block with the fast
constructors of ``construct``.

Any other line (other words or orders, brackets, variables, ``$``, ``#``, ``%``, ``L``,
``/``, ``(``, lower case, ...) does not match and is decoded by the general path
(``Decoder.slow_step``: parser, executor, control flow). While an axis is released
(``#AX RELEASE``), a machining coordinate system is active (``#CS``) or a call pattern
is being defined (``#PATTERN BEGIN``), every line goes there. Under a zero offset or a
tool length (``G54``.., ``D``) the hot path adds the program shift to absolute words, as
the general path does (``BlockExecutor.program_shift``; read again after every line of
the general path, which is where G54, D or the plane change). A matching line that would be
an error (arc end point off the circle, no F yet, I/J/K in a G1 block, a malformed
number such as ``X1.2.3``) goes there too, untouched: the general path is the reference
and raises the error with its exact column. So the hot path decodes only valid lines,
with the same result as the general path (the tests decode programs both ways).

Why generated code: the loop is compiled once per channel axis list from the template
below, so the axis handling is straight-line code over local variables (``p0, p1, ...``
the position, ``e0, e1, ...`` the end point) instead of loops over tuples, and the
whole decoder runs in this one generator (no ``yield from`` per block). That is what
lets the decoder run at more than half the speed of a bare ``str.split`` tokenizer.
``loop_source(axes)`` shows the generated code.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Iterator
from functools import lru_cache
from typing import cast

from .blockexec import FEED_MAX_MM_MIN
from .blocks import Block, Compensation, Motion, MotionKind, SourceRef, StopKind
from .check import BATCH_LINES, PointBatch
from .construct import (
    FAST,
    BlockTwin,
    MotionTwin,
    SourceRefTwin,
    make_block,
    make_motion,
    make_source,
)
from .contour import LOOP_MARKERS
from .geometry import ARC_TOLERANCE_MM
from .modal import DistanceMode
from .work_guard import LOOK_EVERY_STEPS

# a number: at most 20 digits and dots, so always finite; float() rejects "1.2.3"
_NUM = r"([-+]?[0-9.]{1,20}+)[ \t]*+"
_G_MOTION = {"0": MotionKind.RAPID, "1": MotionKind.LINEAR, "2": MotionKind.ARC_CW,
             "3": MotionKind.ARC_CCW}

_TEMPLATE = '''
def run(decoder):
    frames = decoder.frames
    modal = decoder.modal
    manual = decoder.manual
    executor = decoder.executor
    slow_step = decoder.slow_step
    look = decoder.look
    match = MATCH
    new = NEW
    # the work counter (work_guard): steps so far, the step of the last block, the step
    # of the next look at the run (RESET, the endless-program guard)
    work = progress = 0
    look_at = LOOK_EVERY
    while True:
        # (re)load the running frame and the modal state: the general path may have
        # called, returned, jumped or changed G90/G91, the plane, F, D, ...
        frame = frames[-1]
        program = frame.program
        file = program.name
        end = frame.section.end
        i = frame.index
        # the page of lines in memory that holds line i (text_pages): the hot path runs
        # to its end at most, then takes the next one
        if i < end:
            window = program.src.window(i)
            lines, offsets, base, page_end = window.lines, window.offsets, window.first, window.stop
        else:
            page_end = i
        pos = modal.position_mm
        {unpack_pos} = pos
        kind = modal.motion
        feed = None if modal.feed_mm_min is None else modal.feed_mm_min / 60.0
        incremental = modal.distance == INCREMENTAL
        comp = modal.compensation
        look_ahead = modal.look_ahead_mark  # LA_ON: the parameters in effect, else None
        radius = executor.tool_radius(modal.tool_offset) or 0.0
        # zero offset + tool length (G54.., D): added to absolute axis words
        shift = executor.program_shift()
        {unpack_shift} = shift or pos
        plane, line_plane, roles, outside = executor.arc_setup(modal.plane)
        role_i, role_j, role_k = roles
        # with an axis released (#AX RELEASE) every line takes the general path, which
        # rejects the words of released axes
        fast_end = min({fast_end}, page_end)
{setup}
        try:
            while i < fast_end:
                m = match(lines[i - base])
                if m is None:
                    break
                ws, number, gcode, {axis_texts}, t_i, t_j, t_k, ftext = m.groups()
                k = kind if gcode is None else G_MOTION[gcode]
                try:
                    if ftext is not None:
                        f_new = float(ftext)
                        if not 0.0 < f_new <= FEED_MAX:
                            break
                        feed_k = f_new / 60.0
                    else:
                        feed_k = feed
                    if {no_axis_word} and t_i is None and t_j is None and t_k is None:
                        # modal words only (N, G, F): no block, a step of idle work;
                        # the general path takes the line when it is time to look
                        work += 1
                        if work >= look_at:
                            break
                        if gcode is not None:
                            kind = k
                            modal.motion = k
                        if ftext is not None:
                            feed = feed_k
                            modal.feed_mm_min = f_new
                        i += 1
                        continue
                    if incremental:
{incremental}
                    elif shift is None:
{absolute}
                    else:
{absolute_shifted}
                except ValueError:  # a malformed number: the general path reports it
                    break
                end_pos = ({end_tuple})
                if k is ARC_CW or k is ARC_CCW:  # centre = start + offsets in the plane
                    if feed_k is None or plane is None:
                        break
                    if t_i is None and t_j is None and t_k is None:
                        break
                    try:
                        ci = 0.0 if t_i is None else float(t_i)
                        cj = 0.0 if t_j is None else float(t_j)
                        ck = 0.0 if t_k is None else float(t_k)
                    except ValueError:
                        break
                    cp = cq = 0.0
                    if t_i is not None:
                        if role_i == 0:
                            cp = ci
                        elif role_i == 1:
                            cq = ci
                        else:
                            break
                    if t_j is not None:
                        if role_j == 0:
                            cp = cj
                        elif role_j == 1:
                            cq = cj
                        else:
                            break
                    if t_k is not None:
                        if role_k == 0:
                            cp = ck
                        elif role_k == 1:
                            cq = ck
                        else:
                            break
                    if outside is not None and outside(end_pos) != outside(pos):
                        break  # helix: the general path builds it
                    p, q = plane
                    r_start = HYPOT(cp, cq)
                    if r_start == 0.0:
                        break
                    cp = pos[p] + cp
                    cq = pos[q] + cq
                    if abs(r_start - HYPOT(end_pos[p] - cp, end_pos[q] - cq)) > TOLERANCE:
                        break
{arc_motion}
                else:
                    if t_i is not None or t_j is not None or t_k is not None:
                        break
                    if k is RAPID:
                        f_mm_s = INF
                    elif feed_k is None:
                        break
                    else:
                        f_mm_s = feed_k
                    if end_pos == pos:
                        motion = None
                    else:
{linear_motion}
                # the line is valid: commit the modal state
                kind = k
                modal.motion = k
                feed = feed_k
                if ftext is not None:
                    modal.feed_mm_min = f_new
                pos = end_pos
                {unpack_pos} = end_pos
                modal.position_mm = end_pos
{emit}
        except Exception as exc:  # a decoder bug must still be the program's error
            raise decoder.fault(exc, frame, i) from exc
        frame.index = i
{flush}
        if i == page_end and i < end:  # the page is done (no line stopped the hot path)
            continue
        # the line the hot path did not take: the general path
        block = slow_step(frame)
        work += 1
        if block is not None:
            # a real-time loop marker is no block of the program: the guard ignores it
            if block.contour is None or block.contour.kind not in LOOP_MARKERS:
                progress = work
            yield block
            yield from block.then  # the later steps of a G74 sequence
        if decoder.finished:
            return
        if work >= look_at:
            look_at = work + LOOK_EVERY
            look(work - progress)  # raises on RESET and at the guard
            if decoder.finished:  # syntax check: the guard's error reported, the end
                return
'''

_MOTION_FAST = '''\
{pad}motion = new(MOTION_TWIN)
{pad}motion.kind = k
{pad}motion.start_mm = pos
{pad}motion.end_mm = end_pos
{pad}motion.feed_mm_s = {feed}
{pad}motion.plane = {plane}
{pad}motion.center_mm = {centre}
{pad}motion.compensation = comp
{pad}motion.tool_radius_mm = radius
{pad}motion.__class__ = MOTION'''

_BLOCK_FAST = '''\
                src = new(SOURCE_TWIN)
                src.file = file
                src.line = i + 1
                src.column = len(ws) + 1 if ws else 1
                src.offset = offsets[i - base]
                src.__class__ = SOURCE
                block = new(BLOCK_TWIN)
                block.source = src
                block.number = None if number is None else int(number)
                block.motion = motion
                block.dwell_s = 0.0
                block.stop = NO_STOP
                block.m_functions = ()
                block.spindle_speed_rpm = None
                block.tool = None
                block.manual = manual
                block.axis_exchange = None
                block.contour = None
                block.look_ahead = look_ahead
                block.homing_axes = ()
                block.h_functions = ()
                block.manual_mode = None
                block.spindle_pos_deg = None
                block.trafo = None
                block.trafo_switch = False
                block.then = ()
                block.tooling = None
                block.__class__ = BLOCK'''

_BLOCK_PLAIN = '''\
                block = MAKE_BLOCK(MAKE_SOURCE(file, i + 1, len(ws) + 1, offsets[i - base]),
                                   None if number is None else int(number), motion, 0.0,
                                   NO_STOP, (), None, None, manual, None, None,
                                   look_ahead)'''


_EMIT_BLOCK = '''\
{block}
                i += 1
                progress = work
                yield block'''

# check mode (syntax check, dry run): a record per moving line instead of a Block
# (``motion`` is the arc centre, 0 for a straight line: its record has centre None);
# ``progress`` as where the normal loop yields a Block, so the guard sees the same
_EMIT_RECORD = '''\
                if motion is not None:
                    record((i, k, end_pos, motion or None))
                i += 1
                progress = work'''

_SETUP_RECORDS = '''\
        start_i = i
        start_pos = pos
        records = []
        record = records.append'''

_FLUSH_RECORDS = '''\
        if i > start_i:
            yield POINT_BATCH(program.src, start_i, i, start_pos, plane, records)'''

# a machining coordinate system (#CS), a pattern definition open or #TRAFO ON: the
# general path
_FAST_END = ("i if modal.released_axes or modal.cs or modal.pattern is not None "
             "or modal.settings.trafo else end")
# check mode: compensation and single-stepping take the general path; batches are bounded
_FAST_END_CHECK = ("i if modal.released_axes or modal.cs or modal.pattern is not None "
                   "or modal.settings.trafo or decoder.check.line_by_line or comp != COMP_OFF "
                   "else min(end, i + BATCH_LINES)")


def line_pattern(axes: tuple[str, ...]) -> re.Pattern[str]:
    """The regular expression of a plain motion line for a channel with ``axes``."""
    words = "".join(f"(?:{name}{_NUM})?" for name in axes)
    offsets = "".join(f"(?:{letter}{_NUM})?" for letter in "IJK")
    return re.compile(
        r"([ \t]*+)(?:N([0-9]{1,9}+)[ \t]*+)?(?:G0?([0-3])[ \t]*+)?"
        + words + offsets + f"(?:F{_NUM})?" + r"(?:;|$)"
    )


def loop_source(axes: tuple[str, ...], check: bool = False) -> str:
    """The generated Python source of the decoding loop for ``axes`` (``check``: the
    syntax-check variant that yields ``PointBatch`` records from the hot path)."""
    n = len(axes)
    pad = " " * 24
    unpack = ", ".join(f"p{k}" for k in range(n)) + ("," if n == 1 else "")
    absolute = "\n".join(
        f"{pad}e{k} = p{k} if a{k} is None else float(a{k})" for k in range(n)
    ) or f"{pad}pass"
    absolute_shifted = "\n".join(
        f"{pad}e{k} = p{k} if a{k} is None else float(a{k}) + s{k}" for k in range(n)
    ) or f"{pad}pass"
    incremental = "\n".join(
        f"{pad}e{k} = p{k} if a{k} is None else p{k} + float(a{k})" for k in range(n)
    ) or f"{pad}pass"
    if check:
        arc = " " * 20 + "motion = (cp, cq)"
        linear = pad + "motion = 0"
        block = ""
    elif FAST:
        arc = _MOTION_FAST.format(pad=" " * 20, feed="feed_k", plane="plane",
                                  centre="(cp, cq)")
        linear = _MOTION_FAST.format(pad=pad, feed="f_mm_s", plane="line_plane",
                                     centre="None")
        block = _BLOCK_FAST
    else:
        arc = " " * 20 + ("motion = MAKE_MOTION(k, pos, end_pos, feed_k, plane, (cp, cq), "
                          "comp, radius)")
        linear = pad + ("motion = MAKE_MOTION(k, pos, end_pos, f_mm_s, line_plane, None, "
                        "comp, radius)")
        block = _BLOCK_PLAIN
    return _TEMPLATE.format(
        unpack_pos=unpack,
        axis_texts=", ".join(f"a{k}" for k in range(n)),
        no_axis_word=" and ".join(f"a{k} is None" for k in range(n)) or "True",
        absolute=absolute, incremental=incremental, absolute_shifted=absolute_shifted,
        unpack_shift=", ".join(f"s{k}" for k in range(n)) + ("," if n == 1 else ""),
        end_tuple=", ".join(f"e{k}" for k in range(n)) + ("," if n == 1 else ""),
        arc_motion=arc, linear_motion=linear,
        fast_end=_FAST_END_CHECK if check else _FAST_END,
        emit=_EMIT_RECORD if check else _EMIT_BLOCK.format(block=block),
        flush=_FLUSH_RECORDS if check else "",
        setup=_SETUP_RECORDS if check else "",
    )


@lru_cache(maxsize=16)
def decoding_loop(axes: tuple[str, ...], check: bool = False) -> Callable[..., Iterator[Block]]:
    """The compiled decoding loop for ``axes``: ``loop(decoder)`` yields the blocks
    (``check``: and ``PointBatch`` records of the hot path's lines)."""
    namespace = {
        "MATCH": line_pattern(axes).match, "NEW": object.__new__, "G_MOTION": _G_MOTION,
        "INCREMENTAL": DistanceMode.INCREMENTAL, "RAPID": MotionKind.RAPID,
        "ARC_CW": MotionKind.ARC_CW, "ARC_CCW": MotionKind.ARC_CCW, "INF": math.inf,
        "HYPOT": math.hypot, "FEED_MAX": FEED_MAX_MM_MIN,
        "TOLERANCE": ARC_TOLERANCE_MM, "MOTION_TWIN": MotionTwin, "MOTION": Motion,
        "SOURCE_TWIN": SourceRefTwin, "SOURCE": SourceRef, "BLOCK_TWIN": BlockTwin,
        "BLOCK": Block, "NO_STOP": StopKind.NONE, "MAKE_MOTION": make_motion,
        "MAKE_BLOCK": make_block, "MAKE_SOURCE": make_source, "LOOP_MARKERS": LOOP_MARKERS,
        "POINT_BATCH": PointBatch, "BATCH_LINES": BATCH_LINES, "COMP_OFF": Compensation.OFF,
        "LOOK_EVERY": LOOK_EVERY_STEPS,
    }
    code = compile(loop_source(axes, check),
                   f"<decoding loop {''.join(axes)}{' check' if check else ''}>", "exec")
    exec(code, namespace)  # our own template, no outside input
    # the template defines run(decoder), a generator of Blocks (see loop_source)
    return cast(Callable[..., Iterator[Block]], namespace["run"])
