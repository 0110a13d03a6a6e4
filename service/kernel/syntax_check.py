"""The syntax check (SYNCHK) and the dry run (MACHINE_LOCK) of one program, in its SDA thread.

Both decode the whole program with the decoder's check mode and interpolate to block
end points only: no axis moves, no M/H/T, spindle or dwell is executed, feedhold,
override and feed enables do not matter. Each end point (and each arc's extent) is
checked against the software limit switches (``path.endpoints``); blocks under tool
radius compensation go through the path preparation, so its errors are found too.

* **Syntax check** (``settings`` given): every error is reported with its category and
  decoding goes on (``nc.check``). ``errors_total`` ends the check after that many
  errors (warning ``CHECK_STOPPED_WARNING``), ``errors_per_block`` is the decoder's.
  With ``interactive`` the check waits after each error (``Pause.AFTER_ERROR``) until
  ``resume`` (START) or ``cancel`` (RESET). With ``record_result`` every checked line
  and every error go to ``dec0<channel>.sc``, written in one piece when the check ends.
  Only the first ``max_errors`` errors (``[limits] check_max_errors``) are kept, listed
  and logged; the others are counted (``Progress.left_out``, a line of the log).
* **Dry run** (``settings`` None): the first error ends the run, as in a real run.

A software limit violation ends both with that error. RESET (``cancel``) ends the
decoding at the next line or the next error, even inside a long line. Single step at decoder level
(``single_step``) stops after every NC line (``Pause.SINGLE_STEP``); ``stop`` (STOP)
pauses decoding at the next line or batch (``Pause.STOPPED``); ``resume`` goes on.

The GEO cycle reads ``progress()`` (file position of the decoder, lines and blocks
checked, new errors, pause, end) and shows it; it never waits for the check, except
with the virtual clock, where each cycle lets the check decode ``lines_per_cycle``
lines (``advance``) so that a run is the same cycle by cycle every time.
"""

from __future__ import annotations

import logging
import re
import threading
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field, replace
from enum import IntEnum

from cnc_objects.protocol import check_log
from cnc_objects.protocol.check_log import check_log_name
from cnc_objects.protocol.constants import PROGRAM_MAX_BYTES

from ..machine_config import SyntaxCheckConfig
from .nc import Decoder, ModalState, NcError, NcErrorId
from .nc.blocks import Block, Compensation, StopKind
from .nc.check import CheckAborted, ErrorCategory, PointBatch
from .nc.errors import DecodingCancelled
from .nc.source import NcText, SourceText, strip_comments
from .nc.technology import Surroundings
from .path.endpoints import first_violation
from .path.errors import PathError
from .path.limits import AxisDynamics
from .path.segments import PathPreparation
from .workers import Workers

log = logging.getLogger(__name__)

SYNCHK_WITHOUT_MACHINE_LOCK = 21309  # ISG P-ERR-21309 (warning): MACHINE_LOCK set implicitly
CHECK_STOPPED_WARNING = 21310  # the check ended early: syn_chk.errors_total reached
LINES_PER_CYCLE = 20_000  # virtual clock: lines decoded per GEO cycle
_ADVANCE_POLL_S = 0.02  # how often a cycle waiting for the check looks for a RESET
# errors kept per check (listed, logged); the default of [limits] check_max_errors
CHECK_MAX_ERRORS = 1000
_N_WORD = re.compile(r"[ \t]*N[ \t]*([0-9]+)", re.IGNORECASE)


log_name = check_log_name  # the result file of a check in a channel (``dec01.sc``)


class Pause(IntEnum):
    """Why the check waits."""

    NONE = 0
    AFTER_ERROR = 1  # interactive: an error was reported (X_WaitAfterError)
    SINGLE_STEP = 2  # single step: one NC line was decoded (X_WaitContinue)
    STOPPED = 3  # STOP: decoding interrupted (X_WaitContinue)


@dataclass(frozen=True, slots=True)
class CheckedError:
    """An error the check reported, with its category (None: it ended the run)."""

    error: NcError | PathError
    category: ErrorCategory | None
    file: str = ""
    line: int = 0
    column: int = 0


@dataclass(slots=True)
class Progress:
    """What the GEO cycle shows of the check."""

    file: str = ""
    line: int = 0  # 1-based line of the decoder (0: none yet)
    offset: int = 0  # byte offset of that line
    block_number: int = -1  # its N, -1 when it has none
    lines: int = 0  # NC lines decoded
    blocks: int = 0  # blocks checked (motion lines and other blocks)
    errors: list[CheckedError] = field(default_factory=list)  # not yet taken by GEO
    error_count: int = 0  # all errors found
    left_out: int = 0  # errors counted but not kept (over ``max_errors``)
    pause: Pause = Pause.NONE
    done: bool = False
    failure: CheckedError | None = None  # the error that ended the run
    stopped_early: bool = False  # errors_total reached


class CheckRun:
    """A syntax check or dry run of ``name`` in a thread of its own."""

    def __init__(
        self,
        *,
        channel_id: int,
        name: str,
        text_of: Callable[[str], NcText],
        axes: tuple[str, ...],
        axis_numbers: tuple[int, ...],
        tools: Mapping[int, float],
        contour_lookahead: bool,
        start_mm: tuple[float, ...],
        dynamics: Sequence[AxisDynamics],
        sw_limits_mm: Sequence[tuple[float, float]],
        settings: SyntaxCheckConfig | None,
        single_step: bool,
        deterministic: bool,
        files: Callable[..., None],
        surroundings: Surroundings | None = None,
        modal: ModalState | None = None,
        max_errors: int = CHECK_MAX_ERRORS,
        interrupted: Callable[[], bool] = lambda: False,
        workers: Workers | None = None,
    ) -> None:
        """``workers``: the kernel's worker registry, which starts, counts and at the
        end joins the check's thread (one of its own when not given). ``max_errors``:
        errors kept (listed and logged) per check, the limit ``check_max_errors``; the
        rest are counted only. ``interrupted``: called at each
        poll while ``advance`` waits (the kernel answers the cycle's commands then); True
        once a RESET is queued: ``advance`` stops waiting for the check then."""
        self._interrupted = interrupted
        self.channel_id = channel_id
        self.max_errors = max(1, max_errors)
        self.name = name
        self.settings = settings
        self.errors_per_block = settings.errors_per_block if settings else 0
        self.line_by_line = single_step
        self._text_of = text_of
        self._axes = axes
        self._axis_numbers = axis_numbers
        self._tools = tools
        self._contour_lookahead = contour_lookahead
        self._start = start_mm
        # the modal state the check starts with (the channel's look-ahead defaults ..)
        self._modal = modal if modal is not None else ModalState(position_mm=start_mm)
        self._dynamics = tuple(dynamics)
        self._limits = tuple(sw_limits_mm)
        self._deterministic = deterministic
        self._files = files
        self._record = bool(settings and settings.record_result)
        self._log: list[str] = []
        self._pending_log: list[str] = []  # errors of the line being decoded
        self._log_bytes = 0  # size of the log kept so far (it stops at the store limit)
        self._error_log_bytes = 0  # the errors' part of it (kept up to the store limit)
        self._errors_not_logged = 0  # errors after the log reached the store limit
        self._decoder: Decoder | None = None
        self._sources: dict[str, SourceText] = {}  # files decoded so far, by name
        self._limit_reached = False  # errors_total: the check ends after the current line
        self._cond = threading.Condition()
        self._progress = Progress(file=name)
        self._budget = 0  # virtual clock: lines the check may still decode
        self._pause_wanted = False
        self._cancelled = False
        self._position = start_mm  # where the last checked block ended
        self._prep: PathPreparation | None = None  # blocks under radius compensation
        self._surroundings = surroundings  # cycle parameters (files and messages: none)
        workers = Workers() if workers is None else workers
        self._thread = workers.start(f"cnc-check-ch{channel_id}", self._run, self.cancel)

    # ------------------------------------------------------------ GEO side

    def progress(self) -> Progress:
        """A copy of the progress; the errors reported since the last call move out."""
        with self._cond:
            taken = replace(self._progress)
            self._progress.errors = []
            return taken

    def advance(self, lines: int = LINES_PER_CYCLE) -> None:
        """Virtual clock: let the check decode ``lines`` more lines and wait until it
        did, paused or ended."""
        with self._cond:
            self._budget += lines
            self._cond.notify_all()
            # a long line may take seconds: a queued RESET must not wait for its end
            while not self._cond.wait_for(lambda: self._budget <= 0 or self._progress.pause
                                          or self._progress.done, _ADVANCE_POLL_S):
                if self._interrupted():
                    return

    def resume(self) -> bool:
        """START / RESUME: go on after a pause; False when the check was not paused."""
        with self._cond:
            if self._progress.pause == Pause.NONE and not self._pause_wanted:
                return False
            self._pause_wanted = False
            self._progress.pause = Pause.NONE
            self._cond.notify_all()
            return True

    def stop(self) -> None:
        """STOP: interrupt decoding at the next line or batch."""
        with self._cond:
            self._pause_wanted = True
            self._cond.notify_all()

    def set_single_step(self, on: bool) -> None:
        """Single step at decoder level on or off (from the next line)."""
        self.line_by_line = bool(on)

    def cancel(self) -> None:
        """RESET: end the check; the thread stops soon after (no log is written)."""
        with self._cond:
            self._cancelled = True
            self._cond.notify_all()

    def _is_cancelled(self) -> bool:
        return self._cancelled

    @property
    def pause(self) -> Pause:
        """Why the check waits now (NONE: it does not)."""
        return self._progress.pause

    # ------------------------------------------------------------ decoder callbacks

    def report(self, error: NcError, category: ErrorCategory) -> None:
        """The decoder found ``error`` and goes on after it (syntax check) or stops.

        Only the first ``max_errors`` errors are kept (listed, logged); the others are
        counted (``Progress.left_out``), so a line of 100,000 bad words costs no more
        memory than one of 1,000. After RESET (``cancel``) the next error ends the
        decoding at once."""
        if self._cancelled:
            raise CheckAborted
        if self.settings is None:  # dry run: the first error ends it
            self._end_with(CheckedError(error, category, error.file, error.line, error.column))
            raise CheckAborted
        if self._limit_reached:  # the rest of the line the check ends at
            return
        p = self._progress
        if p.error_count >= self.max_errors:  # counted, not kept: memory stays bounded
            p.error_count += 1  # only this thread writes them; GEO reads a copy
            p.left_out += 1
            if not self._stop_at_total(p) and self.settings.interactive:
                self._wait(Pause.AFTER_ERROR)
            return
        # the traceback holds the parser's frames (and through them the line): not kept
        error.__traceback__ = error.__context__ = None
        checked = CheckedError(error, category, error.file, error.line, error.column)
        if self._record:  # written after the line it belongs to
            # errors have a budget of their own: the checked lines of a big program fill
            # the log, an error at its end must still be in it
            if self._error_log_bytes < PROGRAM_MAX_BYTES:
                entry = _error_line(error, category)
                self._pending_log.append(entry)
                self._log_bytes += len(entry) + 1
                self._error_log_bytes += len(entry) + 1
            else:  # the log is full: counted, not kept (memory stays bounded)
                self._errors_not_logged += 1
        with self._cond:
            p.errors.append(checked)
            p.error_count += 1
            src = self._sources.get(error.file)
            if src is None and self._decoder is not None:
                src = self._decoder.source_of(error.file)
            if src is not None and 0 < error.line <= src.count:  # the decoder is here
                p.file, p.line, p.offset = error.file, error.line, src.offset(error.line - 1)
            if self._stop_at_total(p):
                return
        if self.settings.interactive:
            self._wait(Pause.AFTER_ERROR)

    def _stop_at_total(self, p: Progress) -> bool:
        """``errors_total`` reached: the check ends after this line (True)."""
        total = self.settings.errors_total if self.settings is not None else 0
        if total and p.error_count >= total:
            p.stopped_early = self._limit_reached = True
            return True
        return False

    def line(self, src: SourceText, index: int, after: int) -> None:
        """Lines ``index``..``after``-1 were decoded by the general path."""
        self._lines(src, index, after)
        if self._checkpoint():  # also inside loops that yield nothing: STOP, RESET, budget
            raise CheckAborted
        if self.line_by_line and strip_comments(src.line(index)).strip():  # an NC line
            self._wait(Pause.SINGLE_STEP)

    # ------------------------------------------------------------ SDA thread

    def _run(self) -> None:
        try:
            self._check()
        finally:
            if self._decoder is not None:
                self._decoder.close()  # the program's file (a stream) is read no more
        if self._cancelled:
            return
        self._write_log()
        with self._cond:
            self._progress.done = True
            self._progress.pause = Pause.NONE
            self._cond.notify_all()

    def _check(self) -> None:
        try:
            text = self._text_of(self.name)
            decoder = Decoder(
                text, self.name, axes=self._axes, loader=self._text_of, tools=self._tools,
                modal=self._modal, axis_numbers=self._axis_numbers,
                contour_lookahead=self._contour_lookahead, check=self,
                surroundings=self._surroundings,
            )
            self._sources[self.name] = decoder.source
            self._decoder = decoder
            decoder.cancelled = self._is_cancelled  # RESET ends even a check without errors
            if self._record:
                self._log.append(check_log.header_line(self.name, self.channel_id))
            items: Iterator[Block | PointBatch] = decoder.blocks()  # batches in a check
            for item in items:
                if self._checkpoint():
                    return
                if isinstance(item, PointBatch):
                    if self._batch(item):
                        break
                elif self._block(item):
                    break
            self._flush_prep()
        except (CheckAborted, DecodingCancelled):
            pass
        except (KeyError, FileNotFoundError):  # gone between select and start
            self._end_with(CheckedError(NcError(
                NcErrorId.PROGRAM_NOT_FOUND, self.name, 0, 0,
                f"program {self.name!r} not found"), None, self.name))
        except Exception as exc:  # a fault is the run's error, never a dead thread
            log.exception("syntax check of %s failed", self.name)
            self._end_with(CheckedError(NcError(
                NcErrorId.INTERNAL_ERROR, self.name, 0, 0, f"check fault: {exc!r}"), None,
                self.name))

    def _checkpoint(self) -> bool:
        """Between two items: honour STOP and the virtual clock's budget; True when
        cancelled."""
        if self._limit_reached:  # errors_total was reached outside a line
            raise CheckAborted
        with self._cond:
            while True:
                if self._pause_wanted:
                    self._pause_wanted = False
                    self._progress.pause = Pause.STOPPED
                if self._cancelled:
                    return True
                if self._progress.pause == Pause.NONE and (
                        self._budget > 0 or not self._deterministic):
                    return False
                self._cond.notify_all()  # advance() and the GEO side wait for this
                self._cond.wait()

    def _wait(self, why: Pause) -> None:
        """Pause inside the decoder until ``resume`` (or ``cancel``: ends decoding)."""
        with self._cond:
            self._progress.pause = why
            self._cond.notify_all()
            self._cond.wait_for(lambda: self._cancelled or self._progress.pause == Pause.NONE)
            if self._cancelled:
                raise CheckAborted

    def _lines(self, src: SourceText, first: int, stop: int) -> None:
        if stop <= first:
            return
        self._sources[src.name] = src
        last = stop - 1
        raw = src.line(last)
        m = _N_WORD.match(raw)
        if self._record and self._log_bytes < PROGRAM_MAX_BYTES:
            line = src.line
            name = src.name
            start = len(self._log)
            self._log.extend(f"{name}:{k + 1}: {line(k).rstrip()}" for k in range(first, stop)
                             if strip_comments(line(k)).strip())  # NC lines, not comments
            self._log_bytes += sum(len(entry) + 1 for entry in self._log[start:])
        if self._record:
            self._log.extend(self._pending_log)
            self._pending_log.clear()
        with self._cond:
            p = self._progress
            p.file, p.line, p.offset = src.name, last + 1, src.offset(last)
            p.block_number = int(m.group(1)) if m else -1
            p.lines += stop - first
            self._budget -= stop - first

    def _batch(self, batch: PointBatch) -> bool:
        """Check a batch of plain motion lines; True when a limit ended the run."""
        if self._flush_prep():
            return True
        self._lines(batch.src, batch.first, batch.stop)
        records = batch.records
        if records:
            found = first_violation(batch.start_mm, records, batch.plane, self._limits)
            if found is not None:
                k, error = found
                self._end_with(_limit_error(error, batch.src.name, records[k][0] + 1))
                return True
            self._position = records[-1][2]
        with self._cond:
            self._progress.blocks += len(records)
        return False

    def _block(self, block: Block) -> bool:
        """Check one block of the general path; True when the run ends here."""
        with self._cond:
            self._progress.blocks += 1
        motion = block.motion
        if motion is not None:
            compensated = motion.compensation != Compensation.OFF
            try:
                if compensated or self._prep is not None:
                    # radius compensation: the path preparation checks compensation and
                    # software limits as in a real run
                    if self._prep is None:
                        self._prep = PathPreparation(self._dynamics, motion.start_mm,
                                                     self._limits)
                    self._prep.prepare(block)
                    if not compensated:
                        prep, self._prep = self._prep, None
                        prep.flush()
                else:
                    found = first_violation(motion.start_mm, [(0, motion.kind, motion.end_mm,
                                            motion.center_mm)], motion.plane, self._limits)
                    if found is not None:
                        raise found[1]
            except PathError as error:
                self._prep = None
                if self._path_failure(error, block):
                    return True
            self._position = motion.end_mm
        return block.stop == StopKind.PROGRAM_END

    def _flush_prep(self) -> bool:
        """Release what radius compensation holds back; True when that ended the run."""
        if self._prep is None:
            return False
        prep, self._prep = self._prep, None
        try:
            prep.flush()
        except PathError as error:
            return self._path_failure(error, None)
        return False

    def _path_failure(self, error: PathError, block: Block | None) -> bool:
        """A path preparation error, at the block it names (a block compensation held
        back) or ``block``: a software limit ends the run (True); others are reported
        like decoder errors and the check goes on."""
        named = error.block if error.block is not None else block
        src = named.source if named is not None else None
        file, line, column = (src.file, src.line, src.column) if src else (self.name, 0, 0)
        if error.id.name.startswith("SW_LIMIT"):
            self._end_with(_limit_error(error, file, line, column))
            return True
        self.report(NcError(int(error.id), file, line, column, error.message),
                    ErrorCategory.VALUE)
        self._log.extend(self._pending_log)  # its line is logged already
        self._pending_log.clear()
        return False

    def _end_with(self, checked: CheckedError) -> None:
        if self._record:
            self._log.extend(self._pending_log)
            self._pending_log.clear()
            err = checked.error
            self._log.append(check_log.error_line(int(err.id), "abort", checked.file,
                                                  checked.line, checked.column, err.message))
        with self._cond:
            self._progress.failure = checked

    def _write_log(self) -> None:
        if not self._record:
            return
        self._log.extend(self._pending_log)
        p = self._progress
        how = (f"{check_log.STOPPED}: syn_chk.errors_total reached" if p.stopped_early
               else check_log.ABORTED if p.failure is not None else check_log.COMPLETE)
        end = check_log.end_line(p.lines, p.blocks, p.error_count, how)
        entries = self._log
        if p.left_out:
            entries.append(check_log.left_out_line(
                p.left_out, f"limits.check_max_errors: the first {self.max_errors} are kept"))
        if self._errors_not_logged or self._log_bytes >= PROGRAM_MAX_BYTES:
            # the output area's file limit (one download): the first errors are kept, the checked lines go
            errors = [entry for entry in entries if entry.startswith("error ")]
            left_out = p.left_out
            entries = [entries[0], ("; the checked lines are left out: the log would exceed "
                                    f"the output area's file limit of {PROGRAM_MAX_BYTES} bytes")]
            room = PROGRAM_MAX_BYTES - 400 - sum(len(e) + 1 for e in entries)
            kept = 0
            for entry in errors:
                room -= len(entry) + 1
                if room < 0:
                    break
                kept += 1
            entries += errors[:kept]
            left = len(errors) - kept + self._errors_not_logged + left_out
            if left:
                entries.append(check_log.left_out_line(left, "the output area's file limit"))
        data = ("\n".join(entries) + "\n" + end + "\n").encode()
        self._files(log_name(self.channel_id), data, replace=True)


def _error_line(error: NcError, category: ErrorCategory) -> str:
    """An error as the log writes it (``clients`` parse this form)."""
    return check_log.error_line(int(error.id), category.label, error.file, error.line,
                                error.column, error.message)


def _limit_error(error: PathError, file: str, line: int, column: int = 1) -> CheckedError:
    return CheckedError(error, None, file, line, column)
