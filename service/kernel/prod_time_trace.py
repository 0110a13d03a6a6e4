"""The path of a machining time calculation (PROD_TIME), cycle by cycle, for plots.

With ``ch<c>.prod_time_trace`` TRUE, a PROD_TIME run records after every simulated cycle
the command position of each channel axis, the path distance, the path speed and the
feed limit (F of the block in the interpolator; the axis limit for G0). At the end of
the run (READY or ERROR) the channel writes the rows to ``prodtime0<c>.csv`` in the
output area (the files the kernel writes), where ``cnc plot`` and ``Client.trace_run``
read them.

A run of any length stays bounded: when ``rows_max`` rows are kept, every second one is
dropped and from then on only every second cycle is recorded (the stride doubles each
time), so a long program is thinned evenly, never cut off. The file must also fit one
download (``PROGRAM_MAX_BYTES``, 1 MB, the default of ``[limits] output_max_file_bytes``):
the rows are thinned the same way until it does. The last cycle is always in the file,
so the trace ends at the program's end point.
"""

from __future__ import annotations

from cnc_objects.protocol.constants import PROGRAM_MAX_BYTES

#: one cycle: (time s, position mm per axis..., distance mm, path velocity mm/s, feed
#: limit mm/s, line); its length depends on the channel's axes
Row = tuple[float | int, ...]
TRACE_ROWS_MAX = 20_000  # rows kept at most while the run goes (a plot is ~1,200 px wide)


def trace_file_name(channel_id: int) -> str:
    """The program-store file of a channel's PROD_TIME trace (like dec0<c>.sc)."""
    return f"prodtime0{channel_id}.csv"


class ProdTimeTrace:
    """Rows of (t, positions..., path distance, path speed, feed limit, line) of one run."""

    def __init__(
        self, program: str, channel_id: int, axes: tuple[str, ...], cycle_s: float,
        rows_max: int = TRACE_ROWS_MAX,
    ) -> None:
        if rows_max < 2:
            raise ValueError(f"rows_max must be at least 2, not {rows_max}")
        self.program = program
        self.channel_id = channel_id
        self.axes = axes
        self.cycle_s = cycle_s
        self.rows_max = rows_max
        self.stride = 1  # every stride-th cycle is recorded
        self._rows: list[Row] = []
        self._cycles = 0  # cycles offered so far
        self._last: Row | None = None  # the newest cycle, recorded or not

    def record(
        self, time_s: float, position_mm: tuple[float, ...], distance_mm: float,
        path_velocity_mm_s: float, feed_limit_mm_s: float, line: int,
    ) -> None:
        """One cycle of the run (``time_s`` from the program start)."""
        row = (time_s, *position_mm, distance_mm, path_velocity_mm_s, feed_limit_mm_s, line)
        self._last = row
        if self._cycles % self.stride == 0:
            self._rows.append(row)
            if len(self._rows) >= self.rows_max:
                self._rows = self._rows[::2]  # keeps the first row, halves the rest
                self.stride *= 2
        self._cycles += 1

    @property
    def rows(self) -> list[Row]:
        """The recorded rows, the newest cycle included."""
        if self._last is not None and (not self._rows or self._rows[-1] is not self._last):
            return [*self._rows, self._last]
        return list(self._rows)

    def csv_bytes(self, ended: str, max_bytes: int = PROGRAM_MAX_BYTES) -> bytes:
        """The file: a ``#`` header line, a column line, one line per recorded cycle,
        at most ``max_bytes`` long. ``ended``: how the run ended (READY, ERROR <id>)."""
        lines = [",".join(_cell(v) for v in row) + "\n" for row in self.rows]
        stride = self.stride
        while True:
            axes = ",".join(f"{a}_mm" for a in self.axes)
            head = (
                f"# cnc-objects PROD_TIME trace: program {self.program}, channel "
                f"{self.channel_id}, cycle {self.cycle_s * 1e3:g} ms, every {stride}. "
                f"cycle, ended {ended}\n"
                f"t_s,{axes},path_mm,v_mm_s,feed_limit_mm_s,line\n"
            )
            data = (head + "".join(lines)).encode()
            if len(data) <= max_bytes or len(lines) <= 2:
                return data
            # every second row, the first and the last (the end point) kept
            lines = [*lines[:-1:2], lines[-1]] if len(lines) % 2 == 0 else lines[::2]
            stride *= 2


def _cell(value: float | int) -> str:
    if isinstance(value, int):
        return str(value)
    return f"{value:.9g}"
