"""Program store and channel operations of the client (mixed into ``AsyncClient``).

    await c.upload("part.nc", Path("part.nc").read_bytes())
    await c.run_program("part.nc", channel=1)          # select + START
    status = await c.wait_program(channel=1, timeout_s=60)
    await c.mdi("G1 X10 F600", channel=1)
    result = await c.syntax_check("part.nc", channel=1)   # SYNCHK: nothing moves
    await c.reset_to_standard(channel=1)               # RESET, standard execution mode

Everything goes through objects, the program-store index group and the output area's
(the files the kernel writes: logs, check logs, ``#MSG SAVE``); nothing here knows the
kernel. Waiting polls the channel's objects every ``POLL_S`` of wall time. A command
the channel refuses because it is in ERROR says so, with the channel's errors and that
RESET clears them (a CNC does not start in ERROR).
"""

from __future__ import annotations

import os
import struct
import time
from collections.abc import Callable
from dataclasses import dataclass, fields
from typing import Any, BinaryIO

from cnc_objects.protocol import check_log
from cnc_objects.protocol.check_log import check_log_name
from cnc_objects.protocol.constants import (
    FILE_PATH_GENERIC,
    FILE_PATH_SHIFT,
    MAX_DATA_BYTES,
    OUTPUT_AREA_GROUP,
    PROGRAM_MAX_BYTES,
    PROGRAM_STORE_GROUP,
    UPLOAD_CHUNK_BYTES,
    AmsPort,
    CncPort,
    FileOpenMode,
    SystemServiceGroup,
)
from cnc_objects.protocol.constants import OutputAreaOffset as OutOp
from cnc_objects.protocol.constants import ProgramStoreOffset as Op
from cnc_objects.protocol.datatypes import STRING_ENCODING
from cnc_objects.protocol.errors import AdsReturnCode
from cnc_objects.protocol.file_listing import decode_listing
from cnc_objects.protocol.program_lines import LinesRequest, decode_lines_reply, encode_lines_request
from cnc_objects.protocol.values import (
    ROTARY_AXIS_CODE,
    WORKING_STATES,
    ChannelMode,
    ChannelState,
    ContourBlockType,
    ExecutionMode,
    value_names,
)
from cnc_objects.protocol.wait_reasons import WaitReason, wait_reason_text

from . import names
from .client_core import MixinBase
from .errors import AdsError, AdsTimeoutError, ChannelError
from .execution_mode import describe_execution_mode
from .program_upload import ChunkedUpload
from .units import engineering

POLL_S = 0.01  # how often waiting re-reads the channel state (wall time)

MODES = value_names(ChannelMode)
STATES = value_names(ChannelState)
_ERROR = ChannelState.ERROR
_ERROR_SLOTS = 8
SYNCHK, MACHINE_LOCK = int(ExecutionMode.SYNCHK), int(ExecutionMode.MACHINE_LOCK)
WAIT_REASONS = value_names(WaitReason)
#: Called by a wait each time the channel's wait reason changes: (name, sentence), such
#: as ("FEED_HOLD", "feed hold: waiting for START"); ("NONE", "") when it goes on.
OnWaitReason = Callable[[str, str], None]


def describe_wait_reason(value: int) -> tuple[str, str]:
    """The name and sentence of a value of ``mc_wait_reason_r``."""
    return WAIT_REASONS.get(value, str(value)), wait_reason_text(value)


@dataclass(frozen=True, slots=True)
class ProgramEntry:
    """A file in the service's program store."""

    name: str
    size_bytes: int
    mtime_s: float


CONTOUR_RESPONSE_BLOCKS = 32  # gpCh[i].contour_lookahead.response.block[0..31]
CONTOUR_BLOCK_TYPES: dict[int, str] = {  # as the HMI and `cnc lookahead` show them
    ContourBlockType.LINEAR: "linear", ContourBlockType.CIRCULAR: "circular",
    ContourBlockType.LOG_ON: "LOG ON", ContourBlockType.LOG_PARAM: "LOG PARAM",
    ContourBlockType.LOG_OFF: "LOG OFF", ContourBlockType.POLYNOMIAL: "polynomial",
}


@dataclass(frozen=True, slots=True)
class ContourBlock:
    """One element of a contour look-ahead reply, in HLI units (0.1 um, rad)."""

    block_type: int
    block_number: int
    block_count_r: int
    start_position: float
    length: float
    programmed_radius: float
    compensated_radius: float
    circle_angle: float
    length_min: float
    tangent_variation: float


CONTOUR_BLOCK_FIELDS = tuple(f.name for f in fields(ContourBlock))  # the HLI field names


@dataclass(frozen=True, slots=True)
class ContourReply:
    """The CNC's answer to a contour look-ahead request, with the unit's state."""

    max_dist_prog_start: float  # 0.1 um
    count_logged_blocks: int
    log_active: bool
    blocks: list[ContourBlock]  # up to the first entry of block_type 0


@dataclass(frozen=True, slots=True)
class ChannelStatus:
    """What ``cnc status`` shows of a channel. ``execution_mode``: the mode in effect
    (the names of its bits, ``SYNCHK|MACHINE_LOCK``, or ``standard``); it stays after a
    program ends; ``commanded_execution_mode``: the mode the next program start takes."""

    channel: int
    mode: str
    state: str
    program: str
    file: str
    line: int
    block_number: int
    positions_mm: dict[str, float]
    path_velocity_mm_s: float
    program_time_s: float
    errors: list[str]
    execution_mode: str = "standard"
    commanded_execution_mode: str = "standard"
    single_block: bool = False  # single block is on (mc_active_single_block_r)
    wait_reason: str = "NONE"  # why the channel stands (mc_wait_reason_r), by name
    wait_reason_text: str = ""  # the same as a sentence; empty when it does not stand
    rotary_axes: tuple[str, ...] = ()  # axes whose positions are degrees, not mm


@dataclass(frozen=True, slots=True)
class CheckError:
    """One error a syntax check reported (a record, not an exception): where it is,
    its ISG error id, its category (``term``, ``limit``, ...; ``abort`` for the error
    that ended the check) and its message."""

    file: str
    line: int
    column: int
    id: int
    category: str
    message: str


@dataclass(frozen=True, slots=True)
class CheckResult:
    """The outcome of a syntax check (``syntax_check``), read from ``dec0<c>.sc``.

    ``errors``: the reported errors in log order; ``aborted``: the error that ended the
    check (a software limit violation, a missing program, ...), else None; ``lines``
    and ``blocks``: how many NC lines and blocks were checked; ``stopped_early``: the
    check stopped at ``syn_chk.errors_total``; ``log``: the whole log file;
    ``error_count``: all errors the check found (more than ``errors`` when the log had to
    leave some out: over the service's ``limits.check_max_errors`` or at the output
    area's file limit); ``left_out``: how many of them the log says it does not list.
    """

    errors: tuple[CheckError, ...]
    aborted: CheckError | None
    lines: int
    blocks: int
    log: str
    stopped_early: bool
    error_count: int = 0
    left_out: int = 0

    @property
    def clean(self) -> bool:
        """True when the check found no error and ran to the end."""
        return (not self.errors and not self.error_count and self.aborted is None
                and not self.stopped_early)


_LOG_HEADER, _LOG_END, _LOG_ERROR = check_log.HEADER, check_log.END, check_log.ERROR
_LOG_LEFT_OUT, _LOG_POSITION, _LOG_LINE = (
    check_log.LEFT_OUT, check_log.POSITION, check_log.CHECKED_LINE)


def parse_check_log(text: str, program: str = "") -> CheckResult:
    """Parse a syntax check log (``dec0<c>.sc``; format in ``service/kernel/syntax_check``).

    A file name may hold colons: an error's position is found at ``:<line>:<column>: ``
    and, where its text offers several such places, the split whose file name the log
    (or ``program``) names elsewhere wins. Raises ``ValueError`` when the log has no
    end line (it is not a complete syntax check log).
    """
    entries = text.split("\n")  # names never hold a newline; other breaks are text
    known = {program} if program else set()
    for entry in entries:
        header = _LOG_HEADER.fullmatch(entry)
        if header:
            known.add(header.group(1))
        elif entry and not entry.startswith(";") and not _LOG_ERROR.fullmatch(entry):
            known.update(entry[:m.start()] for m in _LOG_LINE.finditer(entry))
    errors: list[CheckError] = []
    aborted: CheckError | None = None
    end = None
    left_out = 0
    for entry in entries:
        if entry.startswith("; end: "):
            end = _LOG_END.fullmatch(entry) or end
            continue
        more = _LOG_LEFT_OUT.fullmatch(entry)
        if more:
            left_out += int(more.group(1))
            continue
        found = _LOG_ERROR.fullmatch(entry)
        if not found:
            continue
        rest = found.group(3)
        splits = list(_LOG_POSITION.finditer(rest))
        if not splits:
            continue
        where = next((m for m in splits if rest[:m.start()] in known), splits[0])
        error = CheckError(rest[:where.start()], int(where.group(1)), int(where.group(2)),
                           int(found.group(1)), found.group(2), rest[where.end():])
        if error.category == "abort":
            aborted = error
        else:
            errors.append(error)
    if end is None:
        raise ValueError("the log has no '; end: ...' line: it is not a complete syntax check log")
    return CheckResult(tuple(errors), aborted, int(end.group(1)), int(end.group(2)), text,
                       end.group(4).startswith(check_log.STOPPED), int(end.group(3)), left_out)


_U64 = struct.Struct("<Q")
_U32 = struct.Struct("<I")


def _name_bytes(name: str) -> bytes:
    return name.encode(STRING_ENCODING) + b"\x00"


#: Bytes a window of lines may have (``program_lines``): 1000 lines of 250 characters.
LINES_READ_BYTES = 256 * 1024


@dataclass(frozen=True, slots=True)
class ProgramLines:
    """A window of a stored program: ``lines`` from ``first_line`` (from 1), without their
    line ends, and how many lines the program has."""

    first_line: int
    total_lines: int
    lines: list[str]


class ProgramOps(MixinBase):
    """Upload, list, download and delete programs of the service's store."""

    async def upload(
        self, name: str, data: bytes | BinaryIO,
        progress: Callable[[int, int], None] | None = None,
    ) -> None:
        """Store ``data`` as ``name``, replacing an older version atomically. A program
        larger than one chunk (``UPLOAD_CHUNK_BYTES``) goes in chunks, one frame each,
        so its size is bounded by the store's ``[limits] program_max_bytes`` only, not by
        a frame; ``progress(sent_bytes, total_bytes)`` is called after each chunk. A
        failed chunk abandons the upload on the service (nothing is left behind) and
        raises its ``AdsError``. ``data`` may be a binary file open for reading: it is
        read chunk by chunk from where it stands to its end, so a program of 200 MB
        costs the client one chunk of memory, not 200 MB."""
        if not isinstance(data, bytes | bytearray | memoryview):
            await self._upload_file(name, data, progress)
            return
        if len(data) <= UPLOAD_CHUNK_BYTES:
            await self.write_raw(
                CncPort.COM, PROGRAM_STORE_GROUP, Op.UPLOAD, _name_bytes(name) + data)
            if progress is not None:
                progress(len(data), len(data))
            return
        upload = ChunkedUpload(self, name)
        await upload.open()
        view = memoryview(data)
        for start in range(0, len(data), UPLOAD_CHUNK_BYTES):
            await upload.write(view[start:start + UPLOAD_CHUNK_BYTES])
            if progress is not None:
                progress(upload.sent_bytes, len(data))
        await upload.commit()

    def chunked_upload(self, name: str, size_bytes: int | None = None) -> ChunkedUpload:
        """An upload of ``name`` to feed piece by piece (``ChunkedUpload``: open, write,
        commit); ``size_bytes``, when known, lets the service refuse it at the open."""
        return ChunkedUpload(self, name, size_bytes)

    async def program_lines(self, name: str, first_line: int,
                            line_count: int) -> ProgramLines:
        """Lines ``first_line``.. (from 1; at most ``line_count``, as many whole lines as
        ``LINES_READ_BYTES`` hold) of the stored program ``name``, read by the service
        without reading the whole program (``protocol/program_lines``)."""
        raw = await self.read_write_raw(
            CncPort.COM, PROGRAM_STORE_GROUP, Op.READ_LINES,
            encode_lines_request(LinesRequest(name, first_line, line_count)), LINES_READ_BYTES)
        try:
            reply = decode_lines_reply(raw)
        except ValueError as exc:
            raise AdsError(AdsReturnCode.CLIENT_SYNCRESINVALID, str(exc)) from None
        try:
            text = reply.data.decode("utf-8")
        except UnicodeDecodeError:
            text = reply.data.decode("cp1252", errors="replace")  # ISG's encoding
        lines = text.split("\n")
        if lines and lines[-1] == "":
            lines.pop()  # the newline that ends the last line
        return ProgramLines(first_line, reply.total_lines, [s.removesuffix("\r") for s in lines])

    async def _upload_file(
        self, name: str, f: BinaryIO, progress: Callable[[int, int], None] | None,
    ) -> None:
        """``upload`` of a file from where it stands, read one chunk at a time; its size
        is announced at the open (a program over the limits is refused at once). A read
        error of the file abandons the upload (``OSError`` raised)."""
        start = f.tell()
        total = f.seek(0, os.SEEK_END) - start
        f.seek(start)
        if total <= UPLOAD_CHUNK_BYTES:
            await self.upload(name, f.read(), progress)
            return
        upload = ChunkedUpload(self, name, total)
        await upload.open()
        try:
            while chunk := f.read(UPLOAD_CHUNK_BYTES):
                await upload.write(chunk)
                if progress is not None:
                    progress(upload.sent_bytes, max(total, upload.sent_bytes))
        except OSError:
            await upload.abandon()
            raise
        await upload.commit()

    async def download(
        self, name: str, progress: Callable[[int, int], None] | None = None,
    ) -> bytes:
        """The stored content of ``name``. A program larger than one frame comes with the
        system service's file functions (FOPEN, then FREAD frame by frame, FCLOSE: as a
        TwinCAT client reads a file), so its size is bounded by the store only;
        ``progress(received_bytes, total_bytes)`` is called after each frame."""
        try:
            data = await self.read_write_raw(
                CncPort.COM, PROGRAM_STORE_GROUP, Op.DOWNLOAD, _name_bytes(name), MAX_DATA_BYTES
            )
        except AdsError as exc:
            if exc.code != AdsReturnCode.DEVICE_INVALIDSIZE:  # larger than one frame
                raise
        else:
            if progress is not None:
                progress(len(data), len(data))
            return data
        return await self._download_in_frames(name, progress)

    async def _download_in_frames(
        self, name: str, progress: Callable[[int, int], None] | None,
    ) -> bytes:
        total_bytes = next((p.size_bytes for p in await self.programs() if p.name == name), 0)
        opened = await self.read_write_raw(
            AmsPort.SYSTEM_SERVICE, SystemServiceGroup.FOPEN,
            FileOpenMode.READ | FileOpenMode.BINARY | FILE_PATH_GENERIC << FILE_PATH_SHIFT,
            _name_bytes(name), _U32.size)
        handle = _U32.unpack(opened)[0]
        parts: list[bytes] = []
        received = 0
        try:
            while True:
                part = await self.read_write_raw(
                    AmsPort.SYSTEM_SERVICE, SystemServiceGroup.FREAD, handle, b"",
                    PROGRAM_MAX_BYTES)
                if part:
                    parts.append(part)
                    received += len(part)
                    if progress is not None:
                        progress(received, max(total_bytes, received))
                if len(part) < PROGRAM_MAX_BYTES:  # the end
                    break
        finally:
            await self.read_write_raw(
                AmsPort.SYSTEM_SERVICE, SystemServiceGroup.FCLOSE, handle, b"", 0)
        return b"".join(parts)

    async def programs(self) -> list[ProgramEntry]:
        """Every file in the store, sorted by name."""
        raw = await self.read_raw(CncPort.COM, PROGRAM_STORE_GROUP, Op.LIST, MAX_DATA_BYTES)
        return [ProgramEntry(*entry) for entry in decode_listing(raw)]

    async def delete_program(self, name: str) -> None:
        """Remove ``name`` from the store."""
        await self.write_raw(CncPort.COM, PROGRAM_STORE_GROUP, Op.DELETE, _name_bytes(name))

    async def outputs(self) -> list[ProgramEntry]:
        """Every file of the output area (the files the kernel writes: ``#MSG SAVE``,
        ``errors-ch<c>.log``, ``dec0<c>.sc``, ``prodtime0<c>.csv``, cycle results), sorted
        by name; sizes as they will be once the kernel's queued writes are written."""
        raw = await self.read_raw(CncPort.COM, OUTPUT_AREA_GROUP, OutOp.LIST, MAX_DATA_BYTES)
        return [ProgramEntry(*entry) for entry in decode_listing(raw)]

    async def download_output(self, name: str) -> bytes:
        """The content of output file ``name``, with every write the kernel queued for it
        before this request (ADS 0x70C when there is no such file)."""
        return await self.read_write_raw(
            CncPort.COM, OUTPUT_AREA_GROUP, OutOp.DOWNLOAD, _name_bytes(name), MAX_DATA_BYTES
        )

    async def delete_output(self, name: str) -> None:
        """Remove ``name`` from the output area (operator or admin)."""
        await self.write_raw(CncPort.COM, OUTPUT_AREA_GROUP, OutOp.DELETE, _name_bytes(name))


class ChannelOps(ProgramOps):
    """Select, start, hold, resume, reset, manual blocks, status, waiting."""

    #: how the user gives RESET, named in the refusals of a channel in ERROR (cnc-web
    #: names its Reset button)
    reset_hint = "cnc reset"

    async def run_program(self, name: str, channel: int = 1) -> None:
        """Select ``name`` (AUTOMATIC) and START it; returns once the channel is ACTIVE.
        A channel in ERROR refuses (ADS 0x707, naming its errors) until RESET."""
        what = f"start {name!r}"
        await self._command(channel, what, names.ch(channel).mc_command_program_name_w, name)
        await self._command(channel, what, names.ch(channel).mc_command_start_w, True)

    async def start(self, channel: int = 1) -> None:
        """START: run the selected program, or resume after feedhold, M0 or single block."""
        await self._command(channel, "START", names.ch(channel).mc_command_start_w, True)

    async def _command(self, channel: int, what: str, name: str, value: Any) -> None:
        """Write a channel command. The service refuses a channel in ERROR as not ready
        (0x707) in the words of a working channel; that refusal is told as what it is:
        the channel's errors, and that RESET clears them."""
        try:
            await self.write(name, value)
        except AdsError as exc:
            if exc.code != AdsReturnCode.DEVICE_NOTREADY:
                raise
            if await self.read(names.ch(channel).mc_active_state_r) != _ERROR:
                raise
            message = await self._in_error(channel, what)
            raise AdsError(exc.code, message) from None

    async def _in_error(self, channel: int, what: str) -> str:
        """Why ``what`` cannot be done in a channel in ERROR, with its errors."""
        errors = await self.channel_errors(channel)
        listed = "; ".join(errors) if errors else "no error text"
        return (f"channel {channel} is in ERROR ({listed}); {what} needs a RESET first, "
                f"which clears the error ({self.reset_hint})")

    async def hold(self, channel: int = 1) -> None:
        """Feedhold: the path decelerates and stops (HOLD)."""
        await self.write(names.ch(channel).mc_command_hold_w, True)

    async def reset(self, channel: int = 1) -> None:
        """RESET the channel from any state."""
        await self.write(names.ch(channel).mc_command_reset_w, True)

    async def reset_to_standard(self, channel: int = 1) -> None:
        """RESET the channel and command standard execution: execution mode ISG_STANDARD
        (no bit: no SYNCHK, MACHINE_LOCK, PROD_TIME, ...) and ``syn_chk.record_result``
        FALSE, which a syntax check set up by hand leaves behind. Like any execution
        mode, standard takes effect at the next program start. A PLC that commands the
        mode itself (``gpCh[i].decoder_mc_control.execution_mode.enable_w`` TRUE) keeps
        its command."""
        ch = f"ch{channel}"
        await self.reset(channel)
        await self.write(f"{ch}.mc_command_execution_mode_w", 0)
        await self.write(f"{ch}.syn_chk.record_result", False)

    async def mdi(self, blocks: str, channel: int = 1) -> int:
        """Run ``blocks`` as manual blocks; returns the count of finished manual blocks
        before this one (``wait_mdi`` waits until it has grown)."""
        before = await self.read(names.ch(channel).mc_manual_blocks_done_r)
        await self._command(channel, "a manual block", names.ch(channel).mc_command_manual_block_w,
                            blocks)
        return int(before)

    async def channel_errors(self, channel: int = 1) -> list[str]:
        """The channel's error list as readable lines."""
        count = await self.read(names.ch(channel).mc_error_count_r)
        fields = ("id", "file", "line", "column", "text", "warning")
        wanted = [
            f"ch{channel}.mc_error_{k}_{f}_r"
            for k in range(1, min(count, _ERROR_SLOTS) + 1)
            for f in fields
        ]
        if not wanted:
            return []
        values = await self.read_many(wanted)
        lines = []
        for k in range(1, min(count, _ERROR_SLOTS) + 1):
            v = [values[f"ch{channel}.mc_error_{k}_{f}_r"] for f in fields]
            where = f"{v[1]}:{v[2]}:{v[3]}: " if v[1] else ""
            lines.append(f"{'warning' if v[5] else 'error'} {v[0]}: {where}{v[4]}")
        return lines

    async def status(self, channel: int = 1) -> ChannelStatus:
        """Mode, state, program, block and axis positions of a channel."""
        axes = list(await self.browse(f"ch{channel}.ax*.command_position_acs"))
        wanted = [
            f"ch{channel}.{n}"
            for n in (
                "mc_active_mode_r", "mc_active_state_r", "mc_active_program_name_r",
                "mc_active_file_name_r", "mc_active_line_r", "actual_block_number",
                "actual_path_velocity", "program_time", "mc_active_execution_mode_r",
                "mc_command_execution_mode_r", "mc_active_single_block_r", "mc_wait_reason_r",
            )
        ]
        axis_names = [o.name.replace("command_position_acs", "axis_name") for o in axes]
        axis_types = [o.name.replace("command_position_acs", "axis_type") for o in axes]
        values = await self.read_many([*wanted, *axis_names, *axis_types,
                                       *(o.name for o in axes)])
        v: list[Any] = [values[n] for n in wanted]
        positions = {
            # 0.1 um -> mm by the scale the service gives, rounded to 0.1 um: no float noise
            values[an]: engineering(o, values[o.name])
            for an, o in zip(axis_names, axes, strict=True)
        }
        return ChannelStatus(
            channel, MODES.get(v[0], str(v[0])), STATES.get(v[1], str(v[1])), v[2], v[3], v[4],
            v[5], positions, v[6] / 1000, v[7],
            await self.channel_errors(channel) if v[1] == _ERROR else [],
            execution_mode=describe_execution_mode(v[8]),
            commanded_execution_mode=describe_execution_mode(v[9]),
            single_block=bool(v[10]),
            wait_reason=describe_wait_reason(v[11])[0],
            wait_reason_text=describe_wait_reason(v[11])[1],
            rotary_axes=tuple(values[an] for an, at in zip(axis_names, axis_types, strict=True)
                              if values[at] == ROTARY_AXIS_CODE),
        )

    async def contour_lookahead(
        self, start_position: float = 0.0, length: float = 0.0, *, plc_channel: int = 0
    ) -> ContourReply:
        """Ask the CNC for contour elements ahead (FCT-C40) through the control unit
        ``gpCh[plc_channel].contour_lookahead``: ``length`` 0 is mode 1 (the marked area
        from index ``start_position``), else mode 2 (elements starting in the path window
        [start_position, start_position + length], 0.1 um). Writes the request, sets the
        semaphore (the CNC answers before the write is acknowledged), reads the reply."""
        unit = f"gpCh[{plc_channel}].contour_lookahead"
        await self.write(f"{unit}.request.start_position", float(start_position))
        await self.write(f"{unit}.request.length", float(length))
        await self.write(f"{unit}.semaphor_rw", True)
        state = [f"{unit}.semaphor_rw", f"{unit}.state.max_dist_prog_start",
                 f"{unit}.state.count_logged_blocks", f"{unit}.state.f_log_is_active"]
        wanted = [
            f"{unit}.response.block[{k}].{field}"
            for k in range(CONTOUR_RESPONSE_BLOCKS)
            for field in CONTOUR_BLOCK_FIELDS
        ]
        values = await self.read_many([*state, *wanted])
        if values[state[0]]:
            raise AdsTimeoutError(f"{unit}: the CNC has not answered (semaphor_rw still TRUE)")
        blocks = []
        for k in range(CONTOUR_RESPONSE_BLOCKS):
            entry = [values[f"{unit}.response.block[{k}].{f}"] for f in CONTOUR_BLOCK_FIELDS]
            if entry[0] == 0:  # block_type 0 ends the list
                break
            blocks.append(ContourBlock(*entry))
        return ContourReply(values[state[1]], values[state[2]], values[state[3]], blocks)

    async def _wait(self, channel: int, done: Any, timeout_s: float | None,
                    on_wait_reason: OnWaitReason | None, settle_s: float) -> None:
        deadline = None if timeout_s is None else time.monotonic() + timeout_s
        wanted = [names.ch(channel).mc_active_state_r, names.ch(channel).mc_manual_blocks_done_r,
                  names.ch(channel).mc_wait_reason_r]
        reported = current = WaitReason.NONE
        since = time.monotonic()  # when ``current`` was first seen
        while True:
            values = await self.read_many(wanted)
            state, done_count, reason = values[wanted[0]], values[wanted[1]], values[wanted[2]]
            if state == _ERROR:
                raise ChannelError(channel, await self.channel_errors(channel))
            if done(state, done_count):
                return
            now = time.monotonic()
            if reason != current:
                current, since = reason, now
            if on_wait_reason is not None and current != reported and (
                    current == WaitReason.NONE or now - since >= settle_s):
                on_wait_reason(*describe_wait_reason(current))
                reported = current
            if deadline is not None and now > deadline:
                why = ""
                if reason != WaitReason.NONE:
                    name, text = describe_wait_reason(reason)
                    why = f": {text} (wait reason {name})"
                raise AdsTimeoutError(
                    f"channel {channel} still {STATES.get(state, state)} after "
                    f"{timeout_s:g} s{why}"
                )
            await self._t.pause(POLL_S)

    async def wait_program(self, channel: int = 1, timeout_s: float | None = None, *,
                           on_wait_reason: OnWaitReason | None = None,
                           reason_settle_s: float = 0.0) -> None:
        """Wait until the channel's program has ended (READY); ``ChannelError`` when the
        channel went to ERROR, ``AdsTimeoutError`` after ``timeout_s`` (its message names
        why the channel stands). ``on_wait_reason`` is called with each new wait reason
        (name, sentence) once it has held for ``reason_settle_s`` of wall time (so that
        reasons of a moment, such as the first blocks' decoding, can be left out), and
        with ("NONE", "") at once when a reason it was told of has gone."""
        await self._wait(channel, lambda state, _: state not in WORKING_STATES, timeout_s,
                         on_wait_reason, reason_settle_s)

    async def wait_mdi(self, before: int, channel: int = 1, timeout_s: float | None = None,
                       *, on_wait_reason: OnWaitReason | None = None,
                       reason_settle_s: float = 0.0) -> None:
        """Wait until the manual block written after ``before`` finished blocks is done
        (``timeout_s``, ``on_wait_reason`` and ``reason_settle_s`` as for
        ``wait_program``)."""
        await self._wait(
            channel,
            lambda state, count: count > before or state not in WORKING_STATES,
            timeout_s, on_wait_reason, reason_settle_s,
        )

    async def syntax_check(
        self,
        program: str,
        channel: int = 1,
        errors_total: int | None = None,
        timeout_s: float | None = None,
    ) -> CheckResult:
        """Syntax check (ISG FCT-C9) of the stored ``program`` in ``channel``: nothing moves.

        Sets the execution mode SYNCHK | MACHINE_LOCK (0x48), ``syn_chk.record_result``
        TRUE, ``syn_chk.interactive`` FALSE, single block off and, when given,
        ``syn_chk.errors_total`` (0: no limit); selects and starts ``program``; waits
        until the channel is READY or ERROR; reads and parses ``dec0<channel>.sc``.
        Whatever happens, the values it changed are written back afterwards; a check
        that is still running then (``timeout_s`` passed, the wait was interrupted) is
        ended with RESET first. A check ended by an error (a software limit violation)
        is a result (``aborted``), not an exception; the channel stays in ERROR, with
        that error in its error list, until RESET, as after a real run.

        Raises ``AdsError`` when the channel cannot start the check (it is working or in
        ERROR, ``program`` is not stored, the PLC commands another execution mode),
        ``AdsTimeoutError`` after ``timeout_s``, ``ChannelError`` when the channel went
        to ERROR without a check (the start failed).
        """
        ch = f"ch{channel}"
        readback = {
            f"{ch}.mc_command_execution_mode_w": f"{ch}.mc_command_execution_mode_r",
            f"{ch}.mc_command_single_block_w": f"{ch}.mc_active_single_block_r",
            f"{ch}.syn_chk.record_result": f"{ch}.syn_chk.record_result",
            f"{ch}.syn_chk.interactive": f"{ch}.syn_chk.interactive",
            f"{ch}.syn_chk.errors_total": f"{ch}.syn_chk.errors_total",
        }
        wanted: dict[str, Any] = {
            f"{ch}.mc_command_execution_mode_w": SYNCHK | MACHINE_LOCK,
            f"{ch}.mc_command_single_block_w": False,  # else it stops after every line
            f"{ch}.syn_chk.record_result": True,
            f"{ch}.syn_chk.interactive": False,  # else it stops after every error
        }
        if errors_total is not None:
            wanted[f"{ch}.syn_chk.errors_total"] = errors_total
        log_file = check_log_name(channel)
        before = await self._prepare_simulation(
            channel, "a syntax check", wanted, readback, SYNCHK,
            stale_file=log_file)
        changed: list[tuple[str, Any]] = []  # (object, value before), in write order
        started = finished = False
        try:
            await self._write_remembered(wanted, readback, before, changed)
            await self.run_program(program, channel)
            started = True
            result = await self._check_result(program, channel, log_file, timeout_s)
            finished = True
            return result
        finally:
            await self._end_check(channel, changed, cancel=started and not finished,
                                  quiet=not finished)

    async def _prepare_simulation(
        self, channel: int, what: str, wanted: dict[str, Any], readback: dict[str, str],
        mode_bit: int, stale_file: str | None,
    ) -> dict[str, Any]:
        """Before a syntax check or traced PROD_TIME run: read what ``wanted`` will change
        (through ``readback``), refuse a working channel or a PLC-commanded execution mode
        without ``mode_bit``, delete the result file of an earlier run (``stale_file``) so
        that it cannot pass for this one. Returns the values read."""
        ch = f"ch{channel}"
        state_names = [f"{ch}.mc_active_mode_r", f"{ch}.mc_active_state_r"]
        before = await self.read_many([*state_names, *(readback[name] for name in wanted)])
        mode, state = (before[n] for n in state_names)
        if state == _ERROR:  # before anything changes (the last log)
            raise AdsError(AdsReturnCode.DEVICE_NOTREADY, await self._in_error(channel, what))
        if state in WORKING_STATES:
            raise AdsError(
                AdsReturnCode.DEVICE_NOTREADY,
                f"channel {channel} is {MODES.get(mode, mode)}/{STATES.get(state, state)}: "
                f"{what} needs a channel that is not working; hold and RESET first",
            )
        await self._refuse_plc_execution_mode(channel, mode_bit)
        if stale_file is not None:
            try:
                await self.delete_output(stale_file)
            except AdsError as exc:
                if exc.code != AdsReturnCode.DEVICE_NOTFOUND:
                    raise
        return before

    async def _write_remembered(
        self, wanted: dict[str, Any], readback: dict[str, str], before: dict[str, Any],
        changed: list[tuple[str, Any]],
    ) -> None:
        """Write ``wanted``, appending (object, value before) of each change to ``changed``
        (in write order, for ``_end_check``)."""
        for name, value in wanted.items():
            old = before[readback[name]]
            if old != value:
                changed.append((name, old))
                await self.write(name, value)

    async def _refuse_plc_execution_mode(self, channel: int, mode_bit: int) -> None:
        """Refuse a simulation the PLC would turn into a real run: while its control unit
        ``gpCh[i].decoder_mc_control.execution_mode`` is enabled, a program start takes
        the PLC's ``command_w`` (which must hold ``mode_bit``) instead of
        ``mc_command_execution_mode_w``."""
        order = [o.name.lower() for o in await self.browse("ch*.mc_active_state_r")]
        index = order.index(names.ch(channel).mc_active_state_r)  # gpCh[i]: layout position
        unit = f"gpCh[{index}].decoder_mc_control.execution_mode"
        values = await self.read_many([f"{unit}.enable_w", f"{unit}.command_w"])
        command = values[f"{unit}.command_w"]
        if values[f"{unit}.enable_w"] and not command & mode_bit:
            raise AdsError(
                AdsReturnCode.DEVICE_INVALIDSTATE,
                f"channel {channel}: the PLC commands execution mode 0x{command & 0xFFFFFFFF:x} "
                f"({unit}.enable_w is TRUE), so a start would run the program, not simulate it",
            )

    async def _check_result(
        self, program: str, channel: int, log_file: str, timeout_s: float | None
    ) -> CheckResult:
        """Wait for the end of a started check (READY or ERROR) and read its log."""
        ended_in_error: ChannelError | None = None
        try:
            await self.wait_program(channel, timeout_s)
        except ChannelError as exc:  # an error ended the check: it is in the log
            ended_in_error = exc
        except AdsTimeoutError as exc:
            if not exc.detail.startswith(f"channel {channel} still "):
                raise  # a request timed out, not the check
            raise AdsTimeoutError(
                f"syntax check of {program} in channel {channel} did not end within "
                f"{timeout_s:g} s; it is cancelled (RESET)"
            ) from None
        try:
            data = await self.download_output(log_file)
        except AdsError as exc:
            if exc.code != AdsReturnCode.DEVICE_NOTFOUND:
                raise
            if ended_in_error is not None:  # the start failed: no check ran
                raise ended_in_error from None
            raise AdsError(exc.code, f"the syntax check of {program} in channel {channel} "
                           f"ended without writing {log_file} (RESET during the check?)") from None
        text = data.decode("utf-8", errors="replace")
        header = _LOG_HEADER.match(text)
        if header and (header.group(1), int(header.group(2))) != (program, channel):
            raise AdsError(AdsReturnCode.CLIENT_SYNCRESINVALID,
                           f"{log_file} is the log of {header.group(1)} in channel "
                           f"{header.group(2)}, not of {program} in channel {channel}")
        try:
            result = parse_check_log(text, program)
        except ValueError as exc:
            raise AdsError(AdsReturnCode.CLIENT_SYNCRESINVALID, f"{log_file}: {exc}") from None
        if ended_in_error is not None and result.aborted is None:
            raise ended_in_error  # ERROR, but not from the check
        return result

    async def _end_check(
        self, channel: int, changed: list[tuple[str, Any]], cancel: bool, quiet: bool
    ) -> None:
        """RESET a check that still runs (``cancel``), then write back every changed
        value, even when one write fails; the first failure is raised unless ``quiet``
        (an exception is on its way already)."""
        first: AdsError | None = None
        if cancel:
            try:
                state = await self.read(names.ch(channel).mc_active_state_r)
                if state in WORKING_STATES:
                    await self.reset(channel)
            except AdsError as exc:
                first = exc
        for name, old in reversed(changed):
            try:
                await self.write(name, old)
            except AdsError as exc:
                first = first or exc
        if first is not None and not quiet:
            raise first
