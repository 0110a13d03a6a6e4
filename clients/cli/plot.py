"""``cnc plot FILE|NAME [-o out.png]``: a dry run on the service, drawn.

The program runs as a machining time calculation (PROD_TIME) in kernel time, traced cycle
by cycle; no axis of the live machine moves. The PNG shows the XY path (equal scale) and
the path speed over the path distance with the feed limit. Exit 0 written; 4 the run
ended in ERROR (the plot shows the path up to the error; the channel stays in ERROR
until ``cnc reset``); 5 ``--wait-timeout`` passed; 1 ADS error; 2 usage; 3 no service.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import typer

from ..errors import AdsError, ChannelError, ClientValueError
from ..figure_png import PlotExtraMissing, require_matplotlib
from .app import EXIT_USAGE, Settings, command, emit, err
from .machine import (
    EXIT_CHANNEL_ERROR,
    ChannelOption,
    finish_wait,
    local_program,
    store_local,
)

if TYPE_CHECKING:
    from ..path_trace import PathTrace


@command()
def plot(
    ctx: typer.Context,
    program: str = typer.Argument(
        ..., metavar="PROGRAM", help="A local file (uploaded first) or a stored name."),
    output: Path = typer.Option(
        None, "--output", "-o", help="PNG file to write (default: <program stem>.png)."),
    channel: int = ChannelOption,
    axes: str = typer.Option("XY", "--axes", help="The two axes of the path plot, e.g. XZ."),
    width_px: int = typer.Option(1200, "--width", min=300, max=8000, help="Width in pixels."),
    timeout_s: float = typer.Option(
        None, "--wait-timeout", min=0.0, metavar="S",
        help="Give up after S seconds (the run is RESET; exit 5)."),
) -> None:
    """Dry run (PROD_TIME, nothing moves) drawn into a PNG.

    The run goes in kernel time; the PNG shows the XY path and the path speed over the
    path distance with the feed limit.
    """
    settings: Settings = ctx.obj
    if len(axes) != 2:
        err.print(f"error: --axes takes two axis letters such as XY, not {axes!r}")
        raise typer.Exit(EXIT_USAGE)
    try:
        require_matplotlib()  # before the dry run, which would be for nothing without it
    except PlotExtraMissing as exc:
        err.print(f"error: {exc}", markup=False)
        raise typer.Exit(EXIT_USAGE) from None
    name, data = local_program(program)
    target = output if output is not None else Path(Path(name).stem + ".png")
    try:
        with settings.session(f"dry run of {name} in channel {channel}") as c:
            store_local(c, name, data)
            trace: PathTrace = c.trace_run(name, channel, timeout_s)
    except (AdsError, ChannelError, ClientValueError) as exc:
        finish_wait(exc)
    from ..path_plot import plot_trace  # numpy and matplotlib: only for the drawing

    try:
        png = plot_trace(trace, width_px=width_px, x_axis=axes[0], y_axis=axes[1])
    except KeyError as exc:
        err.print(f"error: {exc.args[0]}", markup=False)
        raise typer.Exit(EXIT_USAGE) from None
    try:
        target.write_bytes(png)
    except OSError as exc:
        err.print(f"error: cannot write {target}: {exc.strerror}", markup=False)
        raise typer.Exit(EXIT_USAGE) from None
    length_mm = float(trace.path_mm[-1]) if len(trace.path_mm) else 0.0
    emit(settings, {
        "program": name, "channel": channel, "output": str(target), "ended": trace.ended,
        "program_time_s": trace.program_time_s, "path_mm": length_mm,
        "v_max_mm_s": float(trace.v_mm_s.max()) if len(trace.v_mm_s) else 0.0,
        "rows": len(trace.t_s), "stride": trace.stride,
    }, f"{target}: {name} in channel {channel}, {trace.program_time_s:.3f} s, "
       f"{length_mm:.3f} mm, {len(trace.t_s)} cycles drawn, {trace.ended}")
    if trace.ended != "READY":
        err.print(f"error: the dry run ended in {trace.ended} (channel {channel} stays in "
                  "ERROR until 'cnc reset')", markup=False)
        raise typer.Exit(EXIT_CHANNEL_ERROR)
