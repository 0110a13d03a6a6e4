"""The SDA task of one program run: the decoder in a thread of its own, ahead of motion.

The decoder turns NC text into blocks as fast as the queue to the GEO task takes them;
the queue is bounded, so the decoder never runs further ahead than ``capacity`` blocks
beyond the look-ahead buffer. The GEO cycle takes blocks without waiting (realtime
clock: if the decoder falls behind, the path plans a stop at the last block it has, as a
real CNC does) or, with the virtual clock, waits until the decoder has delivered what
the look-ahead buffer can take, so that a run is the same cycle by cycle every time.

Several texts can be decoded one after the other with one modal state: the extended
manual block mode (ADD_MDI_BLOCK) continues a program with each new manual block.
"""

from __future__ import annotations

import logging
import queue
import threading
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass, replace

from .nc import Decoder, ModalState, NcError, NcErrorId
from .nc.blocks import Block, Compensation, SourceRef, StopKind
from .nc.errors import DecodingCancelled
from .nc.source import NcText
from .nc.technology import Surroundings
from .path.errors import PathError
from .path.section_plan import SectionPlan
from .tooling import tooling_of
from .tooling_view import ChannelTooling
from .workers import Workers

log = logging.getLogger(__name__)

_PUT_POLL_S = 0.05  # how often a decoder waiting on a full queue checks for cancel
_TAKE_POLL_S = 0.02  # how often a cycle waiting for the decoder checks for a RESET


@dataclass(frozen=True, slots=True)
class DecodeEnd:
    """No more blocks will come."""


@dataclass(frozen=True, slots=True)
class Job:
    """One text to decode: a program from the store (``text`` None) or a manual block."""

    name: str
    text: str | None = None
    manual: bool = False


Item = Block | NcError | DecodeEnd | PathError

SECTION_MAX_BLOCKS = 500_000  # an LA_ON section longer than this is planned in parts
SectionPlanner = Callable[[list[Block]], SectionPlan]


class SectionCollector:
    """Collects the blocks of an LA_ON section and hands them over planned.

    A section is a run of blocks decoded under LA_ON; it ends at the first block
    without the mark (LA_OFF), after a block that needs a stop, or at the end of the
    decoding. It may only start where the tool radius compensation holds nothing back
    (the last motion block before it ran with G40): the section is prepared from a
    fresh compensation state, which must be the GEO task's state too. LA_ON blocks
    that cannot start a section pass unplanned.
    """

    def __init__(self, planner: SectionPlanner) -> None:
        self._planner = planner
        self._section: list[Block] = []
        self._compensation_free = True  # nothing held back by the compensation

    @property
    def open(self) -> bool:
        """A section is being collected."""
        return bool(self._section)

    def note(self, block: Block) -> None:
        """A block passing outside any section (keeps the compensation state)."""
        motion = block.motion
        if motion is not None:
            self._compensation_free = motion.compensation == Compensation.OFF

    def push(self, block: Block) -> list[Item]:
        """The items to hand over now (nothing while a section is being collected)."""
        if block.look_ahead is None or not (self._section or self._compensation_free):
            out = self.flush()
            out.append(block)
            self.note(block)
            return out
        self._section.append(block)
        self.note(block)
        if block.needs_stop or len(self._section) >= SECTION_MAX_BLOCKS:
            return self.flush()
        return []

    def flush(self) -> list[Item]:
        """The section so far, planned (with the bottleneck error that cut it short)."""
        if not self._section:
            return []
        plan = self._planner(self._section)
        self._section = []
        out: list[Item] = list(plan.blocks)
        if plan.error is not None:
            out.append(plan.error)
        return out

ProgramLoader = Callable[[str], NcText]  # the text of a program, or its file (a stream)


class DecoderFeed:
    """Decodes jobs in order in one SDA thread and queues the blocks for GEO."""

    def __init__(
        self,
        *,
        channel_id: int,
        axes: tuple[str, ...],
        loader: ProgramLoader,
        tools: Mapping[int, float],
        modal: ModalState,
        capacity: int,
        keep_open: bool = False,
        axis_numbers: tuple[int, ...] | None = None,
        contour_lookahead: bool = False,
        surroundings: Surroundings | None = None,
        section_planner: SectionPlanner | None = None,
        interrupted: Callable[[], bool] = lambda: False,
        skip_levels: int = 0,
        workers: Workers | None = None,
    ) -> None:
        """``contour_lookahead``: FCT_CONTOUR_LAH is enabled (P-CHAN-00650), so the
        decoder accepts ``#CONTOUR LOOKAHEAD``; ``surroundings``: the file store, message
        list and cycle parameters the decoder reaches (``nc.technology``);
        ``section_planner``: plans the LA_ON sections (None: they pass unplanned);
        ``interrupted``: called at each poll while ``take`` waits (the kernel answers
        the cycle's commands then); True once a RESET is queued, so that ``take`` stops
        waiting (a decoder in a loop without blocks would hold the cycle until its loop
        guard); ``workers``: the kernel's worker registry, which starts, counts and at
        the end joins the SDA thread (one of its own when not given)."""
        self._interrupted = interrupted
        self._skip_levels = skip_levels  # lines /n skipped: bit n-1 (block skip switch)
        self._surroundings = surroundings
        self._sections = SectionCollector(section_planner) if section_planner else None
        self._axes = axes
        self._contour_lookahead = contour_lookahead
        self._axis_numbers = axis_numbers
        self._loader = loader
        self._tools = tools
        self.modal = modal
        self.keep_open = keep_open  # extended MDI: wait for more jobs instead of ending
        self._jobs: queue.SimpleQueue[Job | None] = queue.SimpleQueue()
        # (``_take_queued`` drains it under its own lock: ``mutex``, ``queue`` and
        # ``not_full`` are the attributes ``queue.Queue``'s methods use)
        self._out: queue.Queue[Item] = queue.Queue(maxsize=capacity)
        self._cancel = threading.Event()
        self._ended = False
        self._markers: set[int] = set()
        self.decoded_all = False  # the SDA thread has queued its last item
        self._outstanding = 0  # jobs added whose end the GEO side has not taken yet
        workers = Workers() if workers is None else workers
        self._thread = workers.start(f"cnc-sda-ch{channel_id}", self._run, self.cancel)

    # ------------------------------------------------------------ GEO side

    def add(self, job: Job) -> None:
        """Decode ``job`` after the ones before it."""
        self._outstanding += 1
        self._jobs.put(job)

    def finish(self) -> None:
        """End after the jobs already added."""
        self._jobs.put(None)

    def is_marker(self, block: Block) -> bool:
        """True for the end-of-text marker block of a manual block."""
        return id(block) in self._markers

    def take(self, limit: int, wait: bool) -> list[Item]:
        """Up to ``limit`` items; with ``wait``, block until ``limit`` items, the end of
        the jobs added so far, or the end of decoding."""
        items: list[Item] = []
        self._take_queued(limit, items)
        while len(items) < limit and not self._ended:
            try:
                item = self._out.get_nowait()
            except queue.Empty:
                if not wait or self._outstanding <= 0:
                    break
                try:
                    item = self._out.get(timeout=_TAKE_POLL_S)
                except queue.Empty:
                    if self._interrupted():  # RESET is queued: it discards all this
                        break
                    continue
            items.append(item)
            if isinstance(item, DecodeEnd | NcError):
                self._ended = True
            elif id(item) in self._markers:
                self._outstanding -= 1
        return items

    def _take_queued(self, limit: int, items: list[Item]) -> None:
        """Move what is queued already (up to ``limit`` items in all) into ``items`` under
        one lock: what ``get_nowait`` one by one would give, without a lock and a wake-up
        per block (issue 37: a CAM program hands over a block or two in every cycle).
        A decoder waiting for room is woken only at the low-water mark (half the
        queue): ``take`` never waits for it before that, since the queue then holds
        more than the look-ahead buffer can take."""
        out = self._out
        with out.mutex:
            queued = out.queue
            taken = 0
            while queued and len(items) < limit and not self._ended:
                item = queued.popleft()
                taken += 1
                items.append(item)
                if isinstance(item, DecodeEnd | NcError):
                    self._ended = True
                elif id(item) in self._markers:
                    self._outstanding -= 1
            # the decoder waits on a full queue: wake it only once half of the queue is
            # free, so that it decodes a batch of blocks per wake-up instead of a block
            # or two per cycle (each wake-up hands the GIL over twice; issue 37)
            if taken and len(queued) <= out.maxsize // 2:
                out.not_full.notify()

    def ready(self, limit: int) -> bool:
        """``take(limit, wait=True)`` would return at once: ``limit`` items are queued or
        decoding has ended."""
        return self._ended or self.decoded_all or self._out.qsize() >= limit

    def cancel(self) -> None:
        """Stop decoding (RESET); the thread ends soon after."""
        self._cancel.set()
        self._jobs.put(None)

    # ------------------------------------------------------------ SDA thread

    def _put(self, item: Item) -> bool:
        while not self._cancel.is_set():
            try:
                self._out.put(item, timeout=_PUT_POLL_S)
                return True
            except queue.Full:
                continue
        return False

    def _put_all(self, items: list[Item]) -> bool:
        for item in items:
            if not self._put(item):
                return False
        return True

    def _flush_section(self) -> bool:
        """Hand over the LA_ON section collected so far (end of a text, an error)."""
        return self._sections is None or self._put_all(self._sections.flush())

    def _blocks(self, job: Job) -> Iterator[Block]:
        text = job.text if job.text is not None else self._loader(job.name)
        decoder = Decoder(
            text, job.name, axes=self._axes, loader=self._loader, tools=self._tools,
            modal=self.modal, manual=job.manual, axis_numbers=self._axis_numbers,
            contour_lookahead=self._contour_lookahead, surroundings=self._surroundings,
            skip_levels=self._skip_levels,
        )
        decoder.cancelled = self._cancel.is_set
        try:
            yield from self._with_tooling(decoder)
        finally:
            decoder.close()  # a program read as a stream: its file is read no more
        self.modal = decoder.modal

    def _with_tooling(self, decoder: Decoder) -> Iterator[Block]:
        """The decoder's blocks; the first one after the tool, D, plane, zero offset or
        a table changed carries the view the objects show while it runs (``tooling``):
        the kernel shows the block being interpolated, not the decoder's look-ahead
        state (issue 39). An identity check per block: nothing is built while nothing
        changes."""
        modal = decoder.modal
        last: tuple[object, ...] = ()
        shown: ChannelTooling | None = None
        for block in decoder.blocks():
            tables = modal.tooling
            now = (tables.tools, tables.zero_offsets, modal.zero_offset_group,
                   modal.tool_offset, modal.plane, modal.tool, modal.spindle_tool)
            if len(now) != len(last) or any(
                    a is not b and a != b for a, b in zip(now, last, strict=True)):
                last = now
                shown = tooling_of(modal, shown or ChannelTooling(), self._axes)
                block = replace(block, tooling=shown)
            yield block

    def _run(self) -> None:
        try:
            self._decode()
        finally:
            self.decoded_all = True

    def _decode(self) -> None:
        self._job = Job("?")
        try:
            while not self._cancel.is_set():
                job = self._jobs.get()
                if job is None:
                    break
                self._job = job
                sections = self._sections
                for block in self._blocks(job):
                    if sections is None or (block.look_ahead is None and not sections.open):
                        if sections is not None:
                            sections.note(block)
                        if not self._put(block):
                            return
                    elif self._cancel.is_set() or not self._put_all(sections.push(block)):
                        return  # (a block collected into a section is not put: look here)
                    if block.stop == StopKind.PROGRAM_END:  # nothing after M30 is decoded
                        self._put(DecodeEnd())
                        return
                if not self._flush_section():
                    return
                if job.manual:
                    marker = Block(SourceRef(job.name, 0), manual=True)
                    self._markers.add(id(marker))
                    if not self._put(marker):
                        return
                if not self.keep_open:
                    break
            self._put(DecodeEnd())
        except DecodingCancelled:  # RESET while the decoder looped without blocks
            return
        except NcError as exc:
            if self._flush_section():  # the blocks before the error run to their end
                self._put(exc)
        except (KeyError, FileNotFoundError):  # the program vanished between select and start
            name = self._job.name
            self._put(NcError(
                NcErrorId.PROGRAM_NOT_FOUND, name, 0, 0, f"program {name!r} not found"
            ))
        except Exception as exc:  # a decoder fault is the program's error, never a crash
            log.exception("decoder failed on %s", self._job.name)
            self._put(NcError(
                NcErrorId.INTERNAL_ERROR, self._job.name, 0, 0, f"decoder fault: {exc!r}"
            ))
