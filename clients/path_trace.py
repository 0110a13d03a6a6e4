"""Dry runs that return the path: a PROD_TIME run on the service, traced cycle by cycle.

    trace = await c.trace_run("part.nc", channel=1)
    trace.x_mm, trace.y_mm, trace.path_mm, trace.v_mm_s, trace.feed_limit_mm_s

The service runs the program through decoder, look-ahead and interpolator in kernel time
(execution mode PROD_TIME, ``docs/syntax-check.md``): the same cycles as a real run on the
virtual clock, as fast as the CPU allows, and no axis of the live machine moves. With
``ch<c>.prod_time_trace`` TRUE the channel writes each cycle's command positions, path
distance, path speed and feed limit to ``prodtime0<c>.csv`` in the output area (thinned
evenly to at most 100,000 rows), which is read and parsed here.
"""

from __future__ import annotations

import io
import re
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from cnc_objects.protocol.errors import AdsReturnCode

from .channel_ops import ChannelOps
from .errors import AdsError, AdsTimeoutError, ChannelError

if TYPE_CHECKING:
    import numpy as np

PROD_TIME = 0x10  # execution mode bit: machining time calculation (FCT-C9)

_HEADER = re.compile(
    r"# cnc-objects PROD_TIME trace: program (.*), channel (\d+), cycle ([\d.e+-]+) ms, "
    r"every (\d+)\. cycle, ended (.*)"
)


def trace_file_name(channel: int) -> str:
    """The output-area file of a traced PROD_TIME run in ``channel``."""
    return f"prodtime0{channel}.csv"


@dataclass(frozen=True)
class PathTrace:
    """The path of one PROD_TIME run, one row per recorded cycle (numpy arrays).

    ``positions_mm`` maps each channel axis name to its command positions; ``path_mm`` is
    the path distance from the program start, ``v_mm_s`` the path speed, and
    ``feed_limit_mm_s`` the F of the block in the interpolator (the axis limit for G0,
    0 at standstill between blocks). ``stride`` > 1: only every stride-th cycle was kept.
    """

    program: str
    channel: int
    cycle_ms: float
    stride: int
    ended: str  # READY, or ERROR <id>
    t_s: np.ndarray
    positions_mm: dict[str, np.ndarray]
    path_mm: np.ndarray
    v_mm_s: np.ndarray
    feed_limit_mm_s: np.ndarray
    line: np.ndarray

    @property
    def program_time_s(self) -> float:
        """Kernel time from the start to the end of the run."""
        return float(self.t_s[-1]) if len(self.t_s) else 0.0

    def axis(self, name: str) -> np.ndarray:
        """The command positions of the axis ``name`` (case-insensitive)."""
        for axis, values in self.positions_mm.items():
            if axis.upper() == name.upper():
                return values
        raise KeyError(f"the trace has no axis {name!r}; it has {', '.join(self.positions_mm)}")


def parse_trace(text: str) -> PathTrace:
    """Parse a ``prodtime0<c>.csv`` file; ``ValueError`` when it is not one."""
    import numpy as np  # here, not above: the client library (and cnc) starts without numpy

    lines = text.split("\n", 2)
    header = _HEADER.fullmatch(lines[0]) if lines else None
    if header is None or len(lines) < 2:
        raise ValueError("not a PROD_TIME trace (no '# cnc-objects PROD_TIME trace' header)")
    columns = lines[1].split(",")
    if columns[:1] != ["t_s"] or columns[-4:] != ["path_mm", "v_mm_s", "feed_limit_mm_s", "line"]:
        raise ValueError(f"unexpected trace columns: {lines[1]!r}")
    body = lines[2] if len(lines) > 2 else ""
    table = np.loadtxt(io.StringIO(body), delimiter=",", ndmin=2) if body.strip() else (
        np.zeros((0, len(columns))))
    if table.shape[1] != len(columns):
        raise ValueError(f"trace rows have {table.shape[1]} values, the header {len(columns)}")
    axes = {name.removesuffix("_mm"): table[:, k] for k, name in enumerate(columns[1:-4], 1)}
    return PathTrace(
        header.group(1), int(header.group(2)), float(header.group(3)), int(header.group(4)),
        header.group(5), table[:, 0], axes, table[:, -4], table[:, -3], table[:, -2],
        table[:, -1].astype(int),
    )


class TraceOps(ChannelOps):
    """``trace_run``: the traced dry run (mixed into ``AsyncClient``)."""

    async def trace_run(
        self, program: str, channel: int = 1, timeout_s: float | None = None
    ) -> PathTrace:
        """Run the stored ``program`` in ``channel`` as a machining time calculation
        (PROD_TIME, no axis moves) with ``prod_time_trace`` TRUE and return its path.

        The execution mode and ``prod_time_trace`` are written back afterwards, whatever
        happens; a run still going then (``timeout_s`` passed) is ended with RESET. A run
        that ends in ERROR still returns its trace up to the error (``ended`` names it);
        the channel stays in ERROR until RESET, as after a real run. Raises ``AdsError``
        when the channel is working or the program is not stored, ``AdsTimeoutError``
        after ``timeout_s``.
        """
        ch = f"ch{channel}"
        readback = {
            f"{ch}.mc_command_execution_mode_w": f"{ch}.mc_command_execution_mode_r",
            f"{ch}.prod_time_trace": f"{ch}.prod_time_trace",
        }
        wanted = {f"{ch}.mc_command_execution_mode_w": PROD_TIME, f"{ch}.prod_time_trace": True}
        result_file = trace_file_name(channel)
        before = await self._prepare_simulation(
            channel, "a traced dry run", wanted, readback, PROD_TIME,
            stale_file=result_file)
        changed: list[tuple[str, Any]] = []
        started = finished = False
        ended_in_error: ChannelError | None = None
        try:
            await self._write_remembered(wanted, readback, before, changed)
            await self.run_program(program, channel)
            started = True
            try:
                await self.wait_program(channel, timeout_s)
            except ChannelError as exc:  # the trace shows the path up to the error
                ended_in_error = exc
            except AdsTimeoutError as exc:
                if not exc.detail.startswith(f"channel {channel} still "):
                    raise
                raise AdsTimeoutError(
                    f"dry run of {program} in channel {channel} did not end within "
                    f"{timeout_s:g} s; it is cancelled (RESET)") from None
            finished = True
        finally:
            await self._end_check(channel, changed, cancel=started and not finished,
                                  quiet=not finished)
        try:
            data = await self.download_output(result_file)
        except AdsError as exc:
            if exc.code != AdsReturnCode.DEVICE_NOTFOUND:
                raise
            if ended_in_error is not None:  # the start failed: nothing ran
                raise ended_in_error from None
            raise AdsError(exc.code, f"the dry run of {program} in channel {channel} ended "
                           f"without writing {result_file}") from None
        try:
            return parse_trace(data.decode("utf-8", errors="replace"))
        except ValueError as exc:
            raise AdsError(AdsReturnCode.CLIENT_SYNCRESINVALID, f"{result_file}: {exc}") from None
