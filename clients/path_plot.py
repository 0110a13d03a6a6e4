"""The picture of a traced dry run (``cnc plot``): the XY path coloured by the path speed
above, the path speed and the feed limit over the path distance below, in one PNG.

Drawn with matplotlib (the ``cnc-objects[plot]`` extra, imported only when a figure is
made: see ``figure_png``). Units are those of ``PathTrace``: mm and mm/s.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .figure_png import pixel_figure, png_bytes
from .path_trace import PathTrace

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

SPEED_COLORMAP = "viridis"  # perceptually uniform, readable in grey and by the colour-blind
SPEED_COLOR = "tab:blue"
FEED_COLOR = "tab:red"
PATH_WIDTH_PT = 2.0


def plot_trace(
    trace: PathTrace, *, width_px: int = 1200, path_height_px: int = 800,
    speed_height_px: int = 600, x_axis: str = "X", y_axis: str = "Y",
) -> bytes:
    """The PNG (``width_px`` wide, ``path_height_px + speed_height_px`` high) of
    ``trace_figure``. ``KeyError`` when the trace has no axis ``x_axis``/``y_axis``;
    ``PlotExtraMissing`` without matplotlib."""
    return png_bytes(trace_figure(
        trace, width_px=width_px, path_height_px=path_height_px,
        speed_height_px=speed_height_px, x_axis=x_axis, y_axis=y_axis))


def trace_figure(
    trace: PathTrace, *, width_px: int = 1200, path_height_px: int = 800,
    speed_height_px: int = 600, x_axis: str = "X", y_axis: str = "Y",
) -> Figure:
    """The figure of ``trace``: the ``x_axis``/``y_axis`` path at equal scale, coloured by
    the path speed (colorbar in mm/s), then the path speed and the feed limit in mm/s
    over the path distance. The feed limit is left out where the path stands between
    blocks (no block in the interpolator)."""
    x_mm, y_mm = trace.axis(x_axis), trace.axis(y_axis)  # KeyError before any drawing
    fig = pixel_figure(width_px, path_height_px + speed_height_px)
    length_mm = float(trace.path_mm[-1]) if len(trace.path_mm) else 0.0
    fig.suptitle(f"{trace.program}: channel {trace.channel}, {trace.program_time_s:.3f} s, "
                 f"{length_mm:.1f} mm, ended {trace.ended}", wrap=True)
    path_ax, speed_ax = fig.subplots(
        2, 1, height_ratios=[path_height_px, speed_height_px])
    _draw_path(fig, path_ax, trace, x_mm, y_mm, x_axis.upper(), y_axis.upper())
    _draw_speed(speed_ax, trace)
    return fig


def _speed_scale_mm_s(trace: PathTrace) -> float:
    """Top of the speed colour scale: the highest feed limit or speed, so that the colour
    of the path says how near it runs to F."""
    top = max(np.max(trace.feed_limit_mm_s, initial=0.0), np.max(trace.v_mm_s, initial=0.0))
    return float(top) if top > 0.0 else 1.0


def _draw_path(fig: Figure, ax: Axes, trace: PathTrace, x_mm: np.ndarray, y_mm: np.ndarray,
               x_name: str, y_name: str) -> None:
    from matplotlib.collections import LineCollection
    from matplotlib.colors import Normalize

    points = np.column_stack([x_mm, y_mm])
    segments = np.stack([points[:-1], points[1:]], axis=1)  # (n - 1, 2 ends, xy)
    # each piece of path takes the mean speed of its two samples
    v_mm_s = 0.5 * (trace.v_mm_s[:-1] + trace.v_mm_s[1:])
    path = LineCollection(segments, cmap=SPEED_COLORMAP,  # type: ignore[arg-type]  # an (n, 2, 2) array is what it takes; its stubs say Sequence
                          norm=Normalize(0.0, _speed_scale_mm_s(trace)),
                          linewidths=PATH_WIDTH_PT, capstyle="round", joinstyle="round")
    path.set_array(v_mm_s)
    ax.add_collection(path)
    if len(points):  # a run that failed at once has no row
        ax.plot(*points[0], "o", color="black", markerfacecolor="white", label="start")
        ax.plot(*points[-1], "x", color="black", markersize=8, label="end")
        ax.legend(loc="upper right")  # start and end only: the colorbar explains the path
    ax.autoscale_view()
    # equal scale so that a circle stays round; the limits grow to fill the panel
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel(f"{x_name} (mm)")
    ax.set_ylabel(f"{y_name} (mm)")
    ax.set_title(f"{x_name}{y_name} path, coloured by path speed", wrap=True)
    ax.grid(True, alpha=0.3)
    fig.colorbar(path, ax=ax, label="path speed (mm/s)")


def _draw_speed(ax: Axes, trace: PathTrace) -> None:
    feed_mm_s = np.where(trace.feed_limit_mm_s > 0.0, trace.feed_limit_mm_s, np.nan)
    ax.plot(trace.path_mm, trace.v_mm_s, color=SPEED_COLOR, linewidth=1.2, label="path speed")
    # on top and dashed: where the path runs at F, both lines stay visible
    ax.plot(trace.path_mm, feed_mm_s, color=FEED_COLOR, linewidth=1.5, linestyle="--",
            label="feed limit F")
    drawn = (f"1 in {trace.stride} cycles of {trace.cycle_ms:g} ms drawn" if trace.stride > 1
             else f"every cycle of {trace.cycle_ms:g} ms")
    ax.set_title(f"path speed over path distance ({drawn})", wrap=True)
    ax.set_xlabel("path distance (mm)")
    ax.set_ylabel("path speed (mm/s)")
    ax.set_ylim(bottom=0.0)
    ax.margins(x=0.01)
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best")
