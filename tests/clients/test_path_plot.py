"""The figure of ``cnc plot``: what it says (labels with units, legend, colorbar, title)
and where it paints, on the trace of a real dry run on the service.

The PNG is read back with Pillow (a dependency of matplotlib) and located with the
figure's own data-to-pixel transform: the path's colour must sit where the path runs.
"""

from __future__ import annotations

import numpy as np
import pytest

from cnc_objects.clients import Client
from cnc_objects.clients.figure_png import png_bytes
from cnc_objects.clients.path_plot import plot_trace, trace_figure
from cnc_objects.clients.path_trace import PathTrace
from tests.support.path_plot import FEED_RGB, PROGRAM, TOP_SPEED_RGB, png_pixels
from tests.support.service import RunningService


@pytest.fixture(scope="module")
def trace(shared_service: RunningService) -> PathTrace:
    """The traced dry run of PROGRAM (the run restores what it changes)."""
    with Client(shared_service.endpoint) as c:
        c.upload("plot-part.nc", PROGRAM)
        return c.trace_run("plot-part.nc")




def colour_near(img: np.ndarray, row: int, col: int, rgb: tuple[int, ...], tol: int = 4) -> bool:
    """Whether a pixel of the 3 x 3 block around (row, col) has colour ``rgb``."""
    block = img[row - 1 : row + 2, col - 1 : col + 2].astype(int)
    return bool(np.any(np.all(np.abs(block - np.array(rgb)) <= tol, axis=2)))


def test_the_figure_names_what_it_shows_with_units(trace: PathTrace) -> None:
    fig = trace_figure(trace)
    path_ax, speed_ax, colorbar_ax = fig.axes
    assert (path_ax.get_xlabel(), path_ax.get_ylabel()) == ("X (mm)", "Y (mm)")
    assert (speed_ax.get_xlabel(), speed_ax.get_ylabel()) == (
        "path distance (mm)", "path speed (mm/s)")
    assert colorbar_ax.get_ylabel() == "path speed (mm/s)"
    assert path_ax.get_aspect() == 1.0  # equal scale: the half circle stays round
    assert [t.get_text() for t in speed_ax.get_legend().get_texts()] == [
        "path speed", "feed limit F"]
    assert [t.get_text() for t in path_ax.get_legend().get_texts()] == ["start", "end"]
    title = fig.get_suptitle()
    assert "plot-part.nc" in title and f"{trace.program_time_s:.3f} s" in title
    assert "71.4 mm" in title and "READY" in title
    # the feed limit line is F in mm/s where a block is in the interpolator, else a gap
    speed_line, feed_line = speed_ax.get_lines()
    feed = feed_line.get_ydata()
    moving = trace.feed_limit_mm_s > 0.0
    assert np.array_equal(feed[moving], trace.feed_limit_mm_s[moving])
    assert np.all(np.isnan(feed[~moving])) and set(feed[moving]) == {100.0, 50.0}
    assert np.array_equal(speed_line.get_ydata(), trace.v_mm_s)
    # the path is coloured by speed on a 0 .. 100 mm/s scale (the highest F)
    [path] = path_ax.collections
    assert (path.norm.vmin, path.norm.vmax) == (0.0, 100.0)
    assert len(path.get_array()) == len(trace.t_s) - 1


def test_the_path_colour_lies_where_the_path_runs(trace: PathTrace) -> None:
    fig = trace_figure(trace, width_px=900, path_height_px=700, speed_height_px=500)
    img = png_pixels(png_bytes(fig))
    assert img.shape == (1200, 900, 3)
    path_ax, speed_ax, _ = fig.axes

    def pixel(ax, x: float, y: float) -> tuple[int, int]:
        col, up = ax.transData.transform((x, y))
        return img.shape[0] - int(up) - 1, int(col)

    # the middle of the first line and the far end of the half circle, both at F6000
    for x_mm, y_mm in ((10.0, 0.0), (10.0, 10.0)):
        assert colour_near(img, *pixel(path_ax, x_mm, y_mm), TOP_SPEED_RGB), (x_mm, y_mm)
    # inside the half circle nothing is drawn
    assert colour_near(img, *pixel(path_ax, 13.3, 6.1), (255, 255, 255), tol=0)
    assert not colour_near(img, *pixel(path_ax, 13.3, 6.1), TOP_SPEED_RGB, tol=60)
    # the feed limit F3000 (50 mm/s) is drawn over the last line (20 mm, from 51.4 mm)
    row, _ = pixel(speed_ax, 60.0, 50.0)
    left, right = (pixel(speed_ax, s, 50.0)[1] for s in (55.0, 70.0))
    assert any(colour_near(img, row, col, FEED_RGB) for col in range(left, right))


@pytest.mark.parametrize("width_px", [300, 333, 1201])
def test_the_png_has_the_requested_size(trace: PathTrace, width_px: int) -> None:
    png = plot_trace(trace, width_px=width_px, path_height_px=401, speed_height_px=299)
    assert png_pixels(png).shape == (700, width_px, 3)


def test_other_axes_and_unknown_axes(trace: PathTrace) -> None:
    fig = trace_figure(trace, x_axis="x", y_axis="z")
    assert (fig.axes[0].get_xlabel(), fig.axes[0].get_ylabel()) == ("X (mm)", "Z (mm)")
    with pytest.raises(KeyError, match="no axis 'Q'"):
        trace_figure(trace, x_axis="X", y_axis="Q")
