"""``cnc`` commands that operate the machine: program store, run, MDI, hold, status.

    cnc upload FILE [--name NAME]        cnc download NAME [-o FILE]      cnc programs
    cnc outputs                          cnc output NAME [-o FILE]        cnc delete-output NAME
    cnc run FILE|NAME [--channel N] [--wait] [--wait-timeout S]
    cnc mdi "BLOCKS" [--channel N] [--wait] [--wait-timeout S]
    cnc hold [--channel N]
    cnc resume [--channel N] [--wait] [--wait-timeout S]
    cnc reset [--channel N] [--standard]
    cnc status [--channel N]
    cnc lookahead [START] [--length MM] [--index I] [--raw]
    cnc check FILE|NAME [--channel N] [--errors-total K] [--log] [--wait-timeout S]

``--wait`` exits 0 when the program (or manual block) has finished, 4 with the channel's
error text when the channel went to ERROR, 5 when ``--wait-timeout`` passed first (default
600 s; ``--wait-timeout 0`` waits without limit), naming why the channel stands (its wait
reason, ``ch<c>.mc_wait_reason_r``). While it waits, each wait reason that has held
for a second is printed as one line on stderr (``channel 1 waits: feed hold: waiting
for START (FEED_HOLD)``; ``channel 1 goes on`` when it clears). ``status`` shows single
block and the wait reason too. A channel
in ERROR refuses ``run``, ``mdi`` and ``resume`` (exit 1, naming its errors) until
``cnc reset``, as a CNC does; ``cnc reset --standard`` also commands standard execution
(no SYNCHK, MACHINE_LOCK, PROD_TIME bit; ``syn_chk.record_result`` off). ``status`` shows
the execution mode in effect and, when it differs, the one the next start takes.
``check`` exits 0 when the program is clean, 1 when the check found errors or was
aborted, 2 when there is no result (bad usage, no service, an ADS error, ``--wait-timeout``).
"""

from __future__ import annotations

import json
import math
import os
import sys
from collections.abc import Callable
from dataclasses import asdict
from pathlib import Path
from typing import TYPE_CHECKING, Any

import typer

from cnc_objects.protocol.constants import PROGRAM_MAX_BYTES, UPLOAD_CHUNK_BYTES
from cnc_objects.protocol.errors import AdsReturnCode

from ..channel_ops import (
    CONTOUR_BLOCK_TYPES,
    ChannelStatus,
    CheckError,
    CheckResult,
    ContourReply,
    OnWaitReason,
    ProgramEntry,
)
from ..errors import AdsError, AdsTimeoutError, ChannelError, ClientValueError, NoReplyError
from ..units import tidy
from .app import EXIT_USAGE, Settings, app, command, emit, err, fail, out, say_error
from .progress import download_progress, upload_progress

if TYPE_CHECKING:  # a client is made by Settings, when a command connects
    from ..blocking import Client

EXIT_CHANNEL_ERROR = 4
EXIT_WAIT_TIMEOUT = 5

ChannelOption = typer.Option(1, "--channel", "-c", min=1, metavar="N", help="Channel id (default 1).")
WaitOption = typer.Option(False, "--wait", help="Return when finished; non-zero on ERROR.")
WAIT_TIMEOUT_DEFAULT_S = 600.0  # --wait gives up after this long unless --wait-timeout says
# --wait prints a wait reason once it has held this long (wall time): the few cycles a
# start waits for its first blocks, a short dwell or spindle ramp are not news
WAIT_REASON_SETTLE_S = 1.0
WaitTimeoutOption = typer.Option(
    WAIT_TIMEOUT_DEFAULT_S, "--wait-timeout", min=0.0, metavar="S",
    help="With --wait: give up after S seconds (exit 5, naming why the channel stands); "
         "0 = no limit.",
)


def wait_limit_s(timeout_s: float | None) -> float | None:
    """The wait's limit for ``--wait-timeout``: 0 (or none given) waits without limit."""
    return timeout_s or None


def print_wait_reason(channel: int) -> OnWaitReason:
    """The ``on_wait_reason`` of a ``--wait``: one line on stderr per change."""
    def show(name: str, text: str) -> None:
        line = f"channel {channel} goes on" if name == "NONE" else (
            f"channel {channel} waits: {text} ({name})")
        err.print(line, markup=False, emoji=False, highlight=False)
    return show


def finish_wait(exc: Exception) -> None:
    """End a waiting command for ``exc``: 4 channel ERROR, 5 the wait's own timeout, else
    as ``fail`` (a request without reply is 3, not 5)."""
    if isinstance(exc, ChannelError):
        say_error(str(exc))
        raise typer.Exit(EXIT_CHANNEL_ERROR)
    if isinstance(exc, AdsTimeoutError) and not isinstance(exc, NoReplyError):
        say_error(str(exc))
        raise typer.Exit(EXIT_WAIT_TIMEOUT)
    fail(exc)


def store_local(c: Client, name: str, data: Path | None) -> None:
    """Upload a local program (the file ``data`` from ``local_program``, read a chunk at
    a time) before it is used. A role that may not upload is refused with the role that
    may (the service's words) and told how to do without: a program already in the store
    is run by its name."""
    if data is None:
        return
    try:
        with data.open("rb") as f:
            c.upload(name, f)
    except OSError as exc:
        raise ClientValueError(f"cannot read {data}: {exc.strerror}") from None
    except AdsError as exc:
        if exc.code != AdsReturnCode.DEVICE_INVALIDACCESS:
            raise
        raise AdsError(exc.code, f"{exc.detail} (a local file is uploaded first; a program "
                       "in the store runs by its name without an upload: cnc programs lists "
                       "them)") from None


def local_program(program: str) -> tuple[str, Path | None]:
    """``FILE|NAME`` of run/check/plot: (store name, file to upload) for a local file,
    (name, None) for a stored program. An unreadable file exits 2 with its reason. The
    file is read when it is uploaded, a chunk at a time (``store_local``)."""
    local = Path(program)
    if not local.is_file():
        return program, None
    try:
        with local.open("rb"):
            return local.name, local
    except OSError as exc:
        say_error(f"cannot read {local}: {exc.strerror}")
        raise typer.Exit(EXIT_USAGE) from None


@command()
def upload(
    ctx: typer.Context,
    file: Path = typer.Argument(..., metavar="FILE", help="Local NC file."),
    name: str = typer.Option(None, "--name", help="Name in the store (default: file name)."),
) -> None:
    """Upload a local NC file into the service's program store."""
    settings: Settings = ctx.obj
    target = name or file.name
    try:
        f = file.open("rb")  # read a chunk at a time: a 200 MB program costs one chunk
    except OSError as exc:
        say_error(f"cannot read {file}: {exc.strerror}")
        raise typer.Exit(EXIT_USAGE) from None
    with f:
        size = os.fstat(f.fileno()).st_size

        def send(c: Client) -> None:
            f.seek(0)  # from the start, also when the call is made again
            c.upload(target, f, progress)

        with upload_progress(f"upload {target}", size, UPLOAD_CHUNK_BYTES) as progress:
            settings.call(send, f"upload of {target}")
    emit(settings, {"name": target, "size_bytes": size, "ok": True},
          f"uploaded {target} ({size} bytes)")


@command()
def download(
    ctx: typer.Context,
    name: str = typer.Argument(..., metavar="NAME", help="Name in the store."),
    output: Path = typer.Option(None, "--output", "-o",
                                help="Write here (default, or '-': stdout)."),
) -> None:
    """Download a program of the program store."""
    settings: Settings = ctx.obj
    with download_progress(f"download {name}", PROGRAM_MAX_BYTES) as progress:
        data = settings.call(lambda c: c.download(name, progress), f"download of {name}")
    save_download(settings, name, data, output)


def save_download(settings: Settings, name: str, data: bytes, output: Path | None) -> None:
    """Write downloaded ``data`` to ``output`` (None or ``-``: stdout) and say so."""
    if output is None or str(output) == "-":
        sys.stdout.buffer.write(data)
        sys.stdout.flush()
        return
    try:
        output.write_bytes(data)
    except OSError as exc:
        say_error(f"cannot write {output}: {exc.strerror}")
        raise typer.Exit(EXIT_USAGE) from None
    emit(settings, {"name": name, "size_bytes": len(data), "output": str(output)},
          f"downloaded {name} ({len(data)} bytes) to {output}")


@command()
def programs(ctx: typer.Context) -> None:
    """List the program store."""
    settings: Settings = ctx.obj
    list_files(settings, settings.call(lambda c: c.programs(), "the program list"))


def list_files(settings: Settings, entries: list[ProgramEntry]) -> None:
    """Print a file list (one JSON object per file with ``--json``)."""
    for e in entries:
        emit(settings, asdict(e), f"{e.name:40} {e.size_bytes:10d} bytes")
    if not settings.as_json:
        out.print(f"{len(entries)} files")


@command()
def outputs(ctx: typer.Context) -> None:
    """List the output area: the files the kernel writes (#MSG SAVE, cycle results,
    errors-ch<c>.log, dec0<c>.sc, prodtime0<c>.csv)."""
    settings: Settings = ctx.obj
    list_files(settings, settings.call(lambda c: c.outputs(), "the output list"))


@command()
def output(
    ctx: typer.Context,
    name: str = typer.Argument(..., metavar="NAME", help="Name in the output area."),
    output_file: Path = typer.Option(None, "--output", "-o",
                                     help="Write here (default, or '-': stdout)."),
) -> None:
    """Download a file of the output area (logs, check logs, #MSG SAVE files)."""
    settings: Settings = ctx.obj
    data = settings.call(lambda c: c.download_output(name), f"download of output {name}")
    save_download(settings, name, data, output_file)


@command("delete-output")
def delete_output(
    ctx: typer.Context,
    name: str = typer.Argument(..., metavar="NAME", help="Name in the output area."),
) -> None:
    """Delete a file of the output area (operator or admin)."""
    settings: Settings = ctx.obj
    settings.call(lambda c: c.delete_output(name), f"delete of output {name}")
    emit(settings, {"name": name, "deleted": True}, f"deleted output {name}")


def wait_to_end(c: Client, channel: int, timeout_s: float | None) -> ChannelStatus:
    """Wait until the channel's program has ended; print the warnings it raised (the
    channel kept running) on stderr, since a run that only said "finished" would hide
    them; return the channel's status."""
    c.wait_program(channel, wait_limit_s(timeout_s), on_wait_reason=print_wait_reason(channel),
                   reason_settle_s=WAIT_REASON_SETTLE_S)
    for line in c.channel_errors(channel):
        if line.startswith("warning"):
            err.print(line, markup=False, emoji=False)
    return c.status(channel)


def report_finished(settings: Settings, status: ChannelStatus) -> None:
    """The one line (or JSON object) of a program that ran to its end."""
    emit(settings, {"channel": status.channel, "program": status.program, "finished": True,
                    "program_time_s": status.program_time_s},
         f"channel {status.channel}: {status.program} finished in "
         f"{status.program_time_s:.3f} s")


def start_and_report(
    settings: Settings, request: str, channel: int, start: Callable[[Client], None],
    wait: bool, timeout_s: float | None, started: tuple[dict[str, Any], str],
) -> None:
    """``start`` the channel in one session for ``request``; without ``wait`` emit
    ``started`` (record, text), with it wait for the program's end and report it (ERROR,
    the wait's timeout and refusals end through ``finish_wait``)."""
    try:
        with settings.session(request) as c:
            start(c)
            if not wait:
                emit(settings, *started)
                return
            status = wait_to_end(c, channel, timeout_s)
    except (AdsError, ChannelError, ClientValueError) as exc:
        finish_wait(exc)
    report_finished(settings, status)


@command()
def run(
    ctx: typer.Context,
    program: str = typer.Argument(
        ..., metavar="PROGRAM", help="A local file (uploaded first) or a stored name."),
    channel: int = ChannelOption,
    wait: bool = WaitOption,
    timeout_s: float = WaitTimeoutOption,
) -> None:
    """Select a program in AUTOMATIC and START it (a local file is uploaded first)."""
    name, data = local_program(program)

    def start(c: Client) -> None:
        store_local(c, name, data)
        c.run_program(name, channel)

    start_and_report(ctx.obj, f"run of {name} in channel {channel}", channel, start, wait,
                     timeout_s, ({"channel": channel, "program": name, "started": True},
                                 f"channel {channel}: {name} started"))


@command()
def mdi(
    ctx: typer.Context,
    blocks: str = typer.Argument(..., metavar="BLOCKS", help="NC blocks; separate blocks with newlines or a "
                                 "literal \\n (';' starts a comment, as in NC programs)."),
    channel: int = ChannelOption,
    wait: bool = WaitOption,
    timeout_s: float = WaitTimeoutOption,
) -> None:
    """Run manual blocks (MDI) in a channel."""
    settings: Settings = ctx.obj
    text = blocks.replace("\\n", "\n")
    try:
        with settings.session(f"manual block in channel {channel}") as c:
            before = c.mdi(text, channel)
            if wait:
                c.wait_mdi(before, channel, wait_limit_s(timeout_s),
                           on_wait_reason=print_wait_reason(channel),
                           reason_settle_s=WAIT_REASON_SETTLE_S)
    except (AdsError, ChannelError, ClientValueError) as exc:
        finish_wait(exc)
    emit(settings, {"channel": channel, "ok": True, "finished": wait},
          f"channel {channel}: manual block {'finished' if wait else 'started'}")


def _channel_command(method: str, done: str, request: str) -> Callable[..., None]:
    def command(ctx: typer.Context, channel: int = ChannelOption) -> None:
        settings: Settings = ctx.obj
        settings.call(lambda c: getattr(c, method)(channel), f"{request} of channel {channel}")
        emit(settings, {"channel": channel, "ok": True}, f"channel {channel}: {done}")

    return command


app.command("hold", help="Feedhold: the path decelerates and stops (HOLD).")(
    _channel_command("hold", "feedhold", "HOLD")
)


@command()
def resume(
    ctx: typer.Context,
    channel: int = ChannelOption,
    wait: bool = WaitOption,
    timeout_s: float = WaitTimeoutOption,
) -> None:
    """START again after feedhold, M0/M1 or a single-block stop."""
    start_and_report(ctx.obj, f"START of channel {channel}", channel,
                     lambda c: c.start(channel), wait, timeout_s,
                     ({"channel": channel, "ok": True}, f"channel {channel}: resumed"))


@command()
def reset(
    ctx: typer.Context,
    channel: int = ChannelOption,
    standard: bool = typer.Option(
        False, "--standard",
        help="Also command standard execution: execution mode ISG_STANDARD (clears SYNCHK, "
             "MACHINE_LOCK, PROD_TIME, ... set by hand) and syn_chk.record_result off; "
             "from the next program start."),
) -> None:
    """RESET the channel from any state (clears ERROR and its error list).

    With --standard the next program start also runs in standard execution, not as a
    syntax check or dry run: the execution mode bits are cleared and
    syn_chk.record_result is switched off.
    """
    settings: Settings = ctx.obj
    if not standard:
        settings.call(lambda c: c.reset(channel), f"RESET of channel {channel}")
        emit(settings, {"channel": channel, "ok": True}, f"channel {channel}: reset")
        return
    settings.call(lambda c: c.reset_to_standard(channel), f"RESET of channel {channel}")
    emit(settings, {"channel": channel, "ok": True, "execution_mode": "standard"},
         f"channel {channel}: reset, standard execution from the next start")


def _units(rotary_axes: tuple[str, ...]) -> str:
    """The units of a channel's positions: mm, and degrees for its rotary axes."""
    if not rotary_axes:
        return "mm"
    return f"mm; {', '.join(rotary_axes)} in degrees"


@command()
def status(ctx: typer.Context, channel: int = ChannelOption) -> None:
    """Mode, state, execution mode, single block, wait reason, program, block and axis
    positions of a channel.

    The execution mode is shown by the names of its bits (SYNCHK|MACHINE_LOCK) or as
    standard; when the commanded mode differs (it takes effect at the next start), that
    one follows as "next start". In ERROR the channel's errors follow.
    """
    settings: Settings = ctx.obj
    s = settings.call(lambda c: c.status(channel), f"status of channel {channel}")
    positions = "  ".join(f"{n}={v:.4f}" for n, v in s.positions_mm.items())
    mode = f"execution mode {s.execution_mode}"
    if s.commanded_execution_mode != s.execution_mode:  # a mode takes effect at a start
        mode += f" (next start: {s.commanded_execution_mode})"
    waits = f"waits: {s.wait_reason_text} ({s.wait_reason})" if s.wait_reason != "NONE" else (
        "waits: -")
    lines = [
        f"channel {s.channel}: {s.mode}/{s.state}  program {s.program or '-'}",
        mode,
        f"single block {'on' if s.single_block else 'off'}  {waits}",
        (f"block N{s.block_number if s.block_number >= 0 else '-'} {s.file or '-'}:{s.line}  "
         f"v={s.path_velocity_mm_s:.3f} mm/s  t={s.program_time_s:.3f} s"),
        f"positions ({_units(s.rotary_axes)}): {positions}",
        *s.errors,
        *(["RESET clears the error (cnc reset)"] if s.state == "ERROR" else []),
    ]
    emit(settings, asdict(s), "\n".join(lines))


@command()
def lookahead(
    ctx: typer.Context,
    start: float = typer.Argument(
        0.0, metavar="START", help="Mode 1: index in the marked area; mode 2: path distance in mm."),
    length: float = typer.Option(
        0.0, "--length", "-l", min=0.0,
        help="0: mode 1 (by index); else mode 2: window length in mm."),
    index: int = typer.Option(
        0, "--index", "-i", min=0, help="PLC channel index gpCh[i] (channel position from 0)."),
    raw: bool = typer.Option(
        False, "--raw", help="Mode 2: START and --length in the objects' own 0.1 um."),
) -> None:
    """Contour look-ahead (FCT-C40): the contour elements ahead, as the PLC gets them.

    Mode 2 takes START and --length in mm (--raw: in 0.1 um, as the request objects
    hold them); the table shows mm and degrees. --json gives the reply's fields as the
    PLC reads them (distances in 0.1 um, angles in rad).
    """
    settings: Settings = ctx.obj
    unit = f"gpCh[{index}].contour_lookahead"

    def ask(c: Client) -> tuple[ContourReply, float]:
        # the factor of 0.1 um to mm, as the service describes the request's length
        scale = c.describe(f"{unit}.request.length").scale
        mm_per_raw = 1.0 if scale is None else scale.factor
        if length == 0.0 or raw:
            return c.contour_lookahead(start, length, plc_channel=index), mm_per_raw
        return c.contour_lookahead(start / mm_per_raw, length / mm_per_raw,
                                   plc_channel=index), mm_per_raw

    reply, mm_per_raw = settings.call(ask, f"contour look-ahead of gpCh[{index}]")
    if settings.as_json:
        out.print(json.dumps(tidy({
            "max_dist_prog_start": reply.max_dist_prog_start,
            "count_logged_blocks": reply.count_logged_blocks,
            "f_log_is_active": reply.log_active,
            "blocks": [asdict(b) for b in reply.blocks],
        })))
        return
    out.print(f"gpCh[{index}]: {reply.count_logged_blocks} logged, log active "
              f"{'TRUE' if reply.log_active else 'FALSE'}, max_dist_prog_start "
              f"{reply.max_dist_prog_start * mm_per_raw:.4f} mm")
    # plain fixed-width lines: never truncated, whatever the terminal width
    out.print(f"{'k':>3} {'type':<10} {'N':>5} {'count':>5} {'start mm':>10} "
              f"{'length mm':>10} {'R prog mm':>9} {'R comp mm':>9} {'angle deg':>9} "
              f"{'tang deg':>8}")
    first = int(start) if length == 0.0 else 0  # mode 1 numbers the entries by log index
    for k, b in enumerate(reply.blocks, start=first):
        motion = b.block_type in (1, 2, 6)
        kind = CONTOUR_BLOCK_TYPES.get(b.block_type, str(b.block_type))
        size = f"{b.length * mm_per_raw:.4f}" if motion else f"PARAM {b.length:g}"
        number = str(b.block_number) if b.block_number >= 0 else "-"
        out.print(
            f"{k:>3} {kind:<10} "
            f"{number:>5} {b.block_count_r:>5} {b.start_position * mm_per_raw:>10.4f} "
            f"{size:>10} {b.programmed_radius * mm_per_raw:>9.4f} "
            f"{b.compensated_radius * mm_per_raw:>9.4f} "
            f"{math.degrees(b.circle_angle):>9.3f} {math.degrees(b.tangent_variation):>8.3f}"
        )


EXIT_CHECK_ERRORS = 1  # cnc check: the program has errors, or the check was aborted
EXIT_CHECK_TROUBLE = 2  # cnc check: no result (usage, connection, ADS error, timeout)


def _check_record(e: CheckError) -> dict[str, object]:
    return {"file": e.file, "line": e.line, "column": e.column, "id": e.id,
            "category": e.category, "message": e.message}


def _plural(n: int, word: str) -> str:
    return f"{n} {word}{'' if n == 1 else 's'}"


def _check_summary(result: CheckResult, channel: int) -> str:
    lines = _plural(result.lines, "line")
    if result.clean:
        return f"clean: {lines}"
    text = f"{_plural(max(result.error_count, len(result.errors)), 'error')} in {lines}"
    if result.left_out:
        text += f" ({result.left_out} not listed)"
    if result.stopped_early:
        text += ", stopped early: syn_chk.errors_total reached"
    if result.aborted is not None:
        text += (f", aborted by error {result.aborted.id} "
                 f"(channel {channel} is in ERROR until 'cnc reset')")
    return text


@command()
def check(
    ctx: typer.Context,
    program: str = typer.Argument(
        ..., metavar="PROGRAM", help="A local file (uploaded first) or a stored name."),
    channel: int = ChannelOption,
    errors_total: int = typer.Option(
        None, "--errors-total", min=0, max=0xFFFF,
        help="Stop after K errors (syn_chk.errors_total; 0: no limit). Default: as set."),
    show_log: bool = typer.Option(
        False, "--log", help="Print the log dec0<N>.sc (with --json: one {\"log\": ...} line)."),
    timeout_s: float = typer.Option(
        None, "--wait-timeout", min=0.0, metavar="S",
        help="Give up after S seconds (the check is RESET; exit 2)."),
) -> None:
    """Syntax check (SYNCHK | MACHINE_LOCK): report every error, move nothing.

    The program is decoded as in a run; the execution mode and the syn_chk settings are
    restored afterwards. Exit 0 clean, 1 errors or aborted, 2 no result.
    """
    settings: Settings = ctx.obj
    name, data = local_program(program)
    try:
        with settings.session(f"syntax check of {name} in channel {channel}") as c:
            store_local(c, name, data)
            result: CheckResult = c.syntax_check(name, channel, errors_total, timeout_s)
    except (AdsError, ChannelError, ClientValueError) as exc:
        say_error(str(exc))
        raise typer.Exit(EXIT_CHECK_TROUBLE) from None
    if show_log and not settings.as_json:
        out.print(result.log, end="", markup=False, emoji=False, highlight=False)
    found = [*result.errors, *([result.aborted] if result.aborted else [])]
    for e in found:
        if settings.as_json:
            out.print(json.dumps(_check_record(e)), markup=False, emoji=False)
        else:
            out.print(f"{e.file}:{e.line}:{e.column}: error {e.id} ({e.category}): "
                      f"{e.message}", markup=False, emoji=False)
    if show_log and settings.as_json:
        out.print(json.dumps({"log": result.log}), markup=False, emoji=False)
    if not settings.as_json:
        err.print(_check_summary(result, channel), markup=False, emoji=False)
    if not result.clean:
        raise typer.Exit(EXIT_CHECK_ERRORS)
