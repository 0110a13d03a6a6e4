"""The syntax check (SYNCHK) or dry run (MACHINE_LOCK) as a run of the channel.

``CheckRun`` (``syntax_check``) decodes the program in its own thread; this is the GEO
cycle's side of it: each cycle shows where the decoder is (file, line, blocks), lists
the errors found since the last cycle, sets the decoder flags of a pause and answers
the ``Step`` the channel runner turns into its state (HOLD, READY, ERROR).
"""

from __future__ import annotations

from dataclasses import replace

from .alarms import AlarmClass
from .channel_mode import ChannelState
from .nc import ModalState
from .program_run import RunHost, Step
from .state import BLOCK_START_COLUMN, Channel, DecoderFlag, ErrorEntry
from .syntax_check import CHECK_STOPPED_WARNING, CheckRun, Pause
from .wait_reason import WaitReason


class ChannelCheck:
    """A ``CheckRun`` shown in its channel, one GEO cycle at a time."""

    def __init__(self, host: RunHost, channel: Channel, check: CheckRun, *,
                 started_at_s: float, deterministic: bool) -> None:
        self._host = host
        self.channel = channel
        self.check = check
        self.started_at_s = started_at_s
        self._deterministic = deterministic  # virtual clock: the cycle lets the check go on
        self._released = Pause.NONE  # START ended this pause (flag for one cycle)
        self._left_out = 0  # errors counted but not kept (check_max_errors), shown so far
        self.failure: ErrorEntry | None = None

    @property
    def ignores_feedhold(self) -> bool:
        """A dry run (MACHINE_LOCK) goes on through feedhold; a syntax check stops."""
        return self.check.settings is None

    def hold(self) -> None:
        """STOP acts on decoding."""
        self.check.stop()

    def resume(self) -> None:
        """Continue decoding (after an error, a step, STOP)."""
        self._released = self.check.pause
        self.check.resume()

    def cancel(self) -> ModalState | None:
        """RESET: end the check (its thread stops soon after)."""
        self.check.cancel()
        return None

    def wait_reason(self) -> int:
        """A check waits for no machine function; its pauses are the channel's HOLD
        (``wait_reason.channel_wait_reason``)."""
        return WaitReason.NONE

    def cycle(self, time_s: float) -> Step:
        """One GEO cycle: show where the decoder is."""
        ch = self.channel
        run = self.check
        run.set_single_step(ch.switches.single_block)
        if self._deterministic and ch.state == ChannelState.ACTIVE:
            run.advance()
        p = run.progress()
        ch.block = ch.block._replace(file_name=p.file, line=p.line, file_offset=p.offset,
                                     block_number=p.block_number, block_count=p.blocks)
        ch.path = ch.path._replace(program_time_s=time_s - self.started_at_s)
        for found in p.errors:
            err = found.error
            self._host.list_error(ErrorEntry(int(err.id), err.message, found.file,
                                               found.line, found.column, warning=True),
                                  to_log=False, keep_last=True,
                                  alarm_class=AlarmClass.CHECK)
        # errors over limits.check_max_errors are counted, not listed
        if p.left_out != self._left_out:
            ch.errors = replace(ch.errors, count=ch.errors.count + p.left_out - self._left_out)
            self._left_out = p.left_out
        flags = ch.program.decoder_flags & DecoderFlag.SYNTAX_CHECK
        if p.pause == Pause.AFTER_ERROR:
            flags |= DecoderFlag.WAIT_AFTER_ERROR
        elif p.pause != Pause.NONE:
            flags |= DecoderFlag.WAIT_CONTINUE
        if self._released == Pause.AFTER_ERROR:  # the implicit enable, cleared this cycle
            flags |= DecoderFlag.SYNTAX_CHECK_RELEASE_CLEARED
        elif self._released != Pause.NONE:
            flags |= DecoderFlag.WAIT_RELEASE_CLEARED
        self._released = Pause.NONE
        if p.done:
            flags = DecoderFlag(0)
        if flags != ch.program.decoder_flags:
            ch.program = replace(ch.program, decoder_flags=flags)
        if p.done:
            if p.failure is not None:
                err = p.failure.error
                self.failure = ErrorEntry(int(err.id), err.message, p.failure.file,
                                            p.failure.line, p.failure.column)
                return Step.FAILED
            if p.stopped_early:
                self._host.list_error(ErrorEntry(
                    CHECK_STOPPED_WARNING, f"syntax check stopped after {p.error_count} errors "
                    "(syn_chk.errors_total, P-CHAN-00019)", p.file, p.line, BLOCK_START_COLUMN,
                    warning=True),
                    alarm_class=AlarmClass.CHECK)
            return Step.ENDED
        if p.pause != Pause.NONE:
            return Step.PAUSED
        return Step.BUSY if ch.state == ChannelState.ACTIVE else Step.WAITING
