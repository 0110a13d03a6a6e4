"""matplotlib figures of an exact size in pixels, rendered to PNG by the Agg backend.

    fig = pixel_figure(1200, 600)
    ax = fig.add_subplot()
    ax.plot(s_mm, v_mm_s, label="path speed")
    png = png_bytes(fig)

matplotlib is the optional extra ``cnc-objects[plot]``. It is imported here, inside the
functions and not at module level, so that ``cnc`` starts without paying for it and
everything but the plots works without the extra. The object-oriented API (``Figure``
with an Agg canvas) keeps no global pyplot state: figures are plain objects, freed when
dropped, and safe to make from any thread.
"""

from __future__ import annotations

import io
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from matplotlib.figure import Figure

PLOT_EXTRA = "cnc-objects[plot]"
DPI = 100  # pixels per inch: 1 pt of line width or font size is 1.39 px


class PlotExtraMissing(ImportError):
    """matplotlib, the ``cnc-objects[plot]`` extra, is not installed."""


def require_matplotlib() -> None:
    """Import matplotlib; ``PlotExtraMissing`` (one line, naming the extra) when absent."""
    try:
        import matplotlib  # noqa: F401
    except ImportError as exc:
        raise PlotExtraMissing(
            f"plots need matplotlib, which is not installed: pip install '{PLOT_EXTRA}'"
        ) from exc


def pixel_figure(width_px: int, height_px: int) -> Figure:
    """An empty figure that renders to exactly ``width_px`` x ``height_px`` pixels, with
    constrained layout (labels, legends and colorbars are fitted inside it)."""
    require_matplotlib()
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    # Agg truncates width_in * dpi to whole pixels, and e.g. 29 / 100 * 100 is 28.999...:
    # half a pixel more makes the truncation land on the requested size.
    fig = Figure(figsize=((width_px + 0.5) / DPI, (height_px + 0.5) / DPI), dpi=DPI,
                 layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def png_bytes(fig: Figure) -> bytes:
    """``fig`` drawn by Agg, as the bytes of an 8-bit RGBA PNG."""
    out = io.BytesIO()
    fig.savefig(out, format="png", dpi=DPI)
    return out.getvalue()
