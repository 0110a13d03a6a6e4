"""The picture of a traced dry run: the XY path above, the path speed over the path
distance with the feed limit below, in one PNG (``cnc plot``)."""

from __future__ import annotations

import numpy as np

from .path_trace import PathTrace
from .png_chart import Series, chart_image, encode_png

PATH_COLOR = (31, 119, 180)
SPEED_COLOR = (31, 119, 180)
FEED_COLOR = (214, 39, 40)


def plot_trace(
    trace: PathTrace, *, width_px: int = 1200, path_height_px: int = 800,
    speed_height_px: int = 600, x_axis: str = "X", y_axis: str = "Y",
) -> bytes:
    """The PNG of ``trace``: ``x_axis``/``y_axis`` path at equal scale, then speed and
    feed limit (mm/s, as the look-ahead plots of the docs) over the path distance. The feed limit is
    left out where the path stands between blocks (no block in the interpolator)."""
    x, y = trace.axis(x_axis), trace.axis(y_axis)
    title = (f"{trace.program}: channel {trace.channel}, {trace.program_time_s:.3f} s, "
             f"{trace.path_mm[-1] if len(trace.path_mm) else 0.0:.1f} mm, {trace.ended}")
    path = chart_image(
        [Series(f"{x_axis}{y_axis} path", x, y, PATH_COLOR, 2)],
        title=title, x_label=f"{x_axis} (mm)", y_label=f"{y_axis} (mm)",
        width_px=width_px, height_px=path_height_px, equal_aspect=True,
    )
    feed = np.where(trace.feed_limit_mm_s > 0.0, trace.feed_limit_mm_s, np.nan)
    speed = chart_image(
        [Series("path speed", trace.path_mm, trace.v_mm_s, SPEED_COLOR, 2),
         Series("feed limit F", trace.path_mm, feed, FEED_COLOR, 1)],
        title=f"path speed over path distance (every {trace.stride}. cycle of "
              f"{trace.cycle_ms:g} ms)",
        x_label="path distance (mm)", y_label="speed (mm/s)",
        width_px=width_px, height_px=speed_height_px,
    )
    return encode_png(np.vstack([path, speed]))
