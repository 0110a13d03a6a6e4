"""Dependency-light PNG line charts: speed-over-distance plots and XY path plots.

    from cnc_objects.clients.png_chart import PALETTE, Series, write_line_chart

    write_line_chart(
        "speed.png",
        [Series("optimum", s_mm, v_opt, color=PALETTE[0]),
         Series("actual", s_mm, v_act, color=PALETTE[1], width_px=2)],
        title="Path speed", x_label="path distance [mm]", y_label="speed [mm/min]",
    )
    # an XY path: same scale on both axes, so a circle stays round
    png = line_chart([Series("path", x_mm, y_mm, color=PALETTE[0])], title="part.nc",
                     x_label="X [mm]", y_label="Y [mm]", equal_aspect=True)

Only numpy, zlib and struct: the chart is drawn into an (H, W, 3) uint8 array, text with
the built-in pixel font below, lines with a vectorised DDA rasteriser, and
``encode_png`` writes the array as an 8-bit RGB PNG.
"""

from __future__ import annotations

import math
import os
import struct
import zlib
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

RGB = tuple[int, int, int]

# Distinct series colours (the Tableau 10 palette), for callers that need defaults.
PALETTE: tuple[RGB, ...] = (
    (31, 119, 180),
    (214, 39, 40),
    (44, 160, 44),
    (255, 127, 14),
    (148, 103, 189),
    (140, 86, 75),
    (227, 119, 194),
    (127, 127, 127),
    (188, 189, 34),
    (23, 190, 207),
)

_WHITE: RGB = (255, 255, 255)
_INK: RGB = (0, 0, 0)  # frame, ticks and text
_GRID: RGB = (225, 225, 225)
_LEGEND_FRAME: RGB = (150, 150, 150)


@dataclass(frozen=True)
class Series:
    """One polyline of a chart: the points (x[i], y[i]) joined in order.

    A NaN (or infinite) x or y breaks the line there; a point with no finite
    neighbour is drawn as a dot. ``color`` is 8-bit RGB, ``width_px`` the line
    width in pixels.
    """

    label: str
    x: Sequence[float] | np.ndarray
    y: Sequence[float] | np.ndarray
    color: RGB
    width_px: int = 1

    def __post_init__(self) -> None:
        if len(self.x) != len(self.y):
            raise ValueError(
                f"series {self.label!r}: {len(self.x)} x values but {len(self.y)} y values"
            )
        if len(self.color) != 3 or not all(0 <= c <= 255 for c in self.color):
            raise ValueError(f"series {self.label!r}: color {self.color!r} is not 8-bit RGB")
        if self.width_px < 1:
            raise ValueError(f"series {self.label!r}: width_px must be >= 1, not {self.width_px}")


def line_chart(series: Sequence[Series], **kw: Any) -> bytes:
    """Draw ``series`` as a line chart and return the PNG file's bytes (the arguments
    of ``chart_image``)."""
    return encode_png(chart_image(series, **kw))


def chart_image(
    series: Sequence[Series],
    *,
    title: str,
    x_label: str,
    y_label: str,
    width_px: int = 1200,
    height_px: int = 600,
    x_range: tuple[float, float] | None = None,
    y_range: tuple[float, float] | None = None,
    equal_aspect: bool = False,
) -> np.ndarray:
    """Draw ``series`` as a line chart: an 8-bit RGB image, ``height_px`` x ``width_px``
    x 3 (``encode_png`` makes a PNG of it; several stack with ``np.vstack``).

    The chart has a title, a framed plot area with grid lines at 1/2/5 x 10^k ticks,
    tick labels, axis labels and, right of the plot, a legend of the series labels.
    ``x_range``/``y_range`` are (low, high) in data units; by default they cover the
    data with a small margin, and y starts at 0 when no y is negative (speed plots).
    Anything outside the ranges is clipped. ``equal_aspect=True`` (for XY path plots)
    widens one range so that both axes have the same scale; y then does not start
    at 0 by default.
    """
    data = [(np.asarray(s.x, dtype=float), np.asarray(s.y, dtype=float)) for s in series]
    if x_range is None:
        x_range = _auto_range([x for x, _ in data], from_zero=False)
    if y_range is None:
        y_range = _auto_range([y for _, y in data], from_zero=not equal_aspect)
    scale = max(1, min(width_px, height_px) // 300)  # 2 for the default 1200 x 600
    title_scale = _title_scale(title, width_px, scale)
    legend = _legend_lines(series, width_px, scale)
    area = _fit_plot_area(
        width_px,
        height_px,
        scale,
        _checked_range(x_range, "x_range"),
        _checked_range(y_range, "y_range"),
        equal_aspect,
        title_h=_GLYPH_H * title_scale if title else 0,
        has_x_label=bool(x_label),
        has_y_label=bool(y_label),
        legend_w=_legend_width(legend, scale),
    )

    img = np.full((height_px, width_px, 3), _WHITE, dtype=np.uint8)
    _draw_grid(img, area)
    for s, (x, y) in zip(series, data):
        _draw_polyline(img, area, x, y, s.color, s.width_px)
    _draw_frame_and_ticks(img, area, scale)
    _draw_titles(img, area, scale, title_scale, (title, x_label, y_label))
    _draw_legend(img, area, scale, legend, series)
    return img


def write_line_chart(path: str | os.PathLike[str], series: Sequence[Series], **kw: Any) -> None:
    """Write ``line_chart(series, **kw)`` to the PNG file ``path``."""
    png = line_chart(series, **kw)
    with open(path, "wb") as f:
        f.write(png)


def encode_png(rgb: np.ndarray) -> bytes:
    """Encode an (H, W, 3) uint8 array as an 8-bit RGB PNG (filter type 0 on every row)."""
    if rgb.ndim != 3 or rgb.shape[2] != 3 or rgb.dtype != np.uint8:
        raise ValueError(f"need an (H, W, 3) uint8 array, got {rgb.shape} {rgb.dtype}")
    height, width = rgb.shape[:2]
    rows = np.zeros((height, 1 + 3 * width), dtype=np.uint8)  # column 0: filter type 0
    rows[:, 1:] = rgb.reshape(height, 3 * width)
    header = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)  # 8 bit, RGB, no interlace
    return b"".join((
        b"\x89PNG\r\n\x1a\n",
        _png_chunk(b"IHDR", header),
        _png_chunk(b"IDAT", zlib.compress(rows.tobytes(), 6)),
        _png_chunk(b"IEND", b""),
    ))  # fmt: skip


def _png_chunk(kind: bytes, payload: bytes) -> bytes:
    """A PNG chunk: length, type, payload and the CRC-32 of type and payload."""
    crc = zlib.crc32(kind + payload)
    return struct.pack(">I", len(payload)) + kind + payload + struct.pack(">I", crc)


# --- data ranges and ticks -------------------------------------------------------


def _checked_range(r: tuple[float, float], name: str) -> tuple[float, float]:
    lo, hi = float(r[0]), float(r[1])
    if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
        raise ValueError(f"{name} must be finite (low, high) with low < high, not {r!r}")
    return lo, hi


def _auto_range(arrays: list[np.ndarray], from_zero: bool) -> tuple[float, float]:
    """The extent of the finite values plus 3 % each side, from 0 if ``from_zero`` and
    none is negative; (0, 1) when there are none."""
    finite = [a[np.isfinite(a)] for a in arrays]
    finite = [a for a in finite if a.size]
    if not finite:
        return 0.0, 1.0
    lo = min(float(a.min()) for a in finite)
    hi = max(float(a.max()) for a in finite)
    if from_zero and lo >= 0:
        return 0.0, (1.03 * hi if hi > 0 else 1.0)
    if hi == lo:  # a constant: centre it in a span of its own size (or of 1 around 0)
        half = abs(lo) / 2 or 0.5
        lo, hi = lo - half, hi + half
    margin = 0.03 * (hi - lo)
    return lo - margin, hi + margin


def _nice_step(min_step: float) -> float:
    """The smallest 1, 2 or 5 x 10^k that is >= ``min_step``."""
    power = 10.0 ** math.floor(math.log10(min_step))
    for m in (1, 2, 5):
        if m * power >= min_step * (1 - 1e-9):
            return m * power
    return 10 * power


def _tick_label(value: float, step: float) -> str:
    """``value`` with as many decimals as the tick step needs ("0.5", "1200")."""
    value += 0.0  # turns -0.0 into 0.0
    decimals = max(0, -math.floor(math.log10(step) + 1e-9))
    if decimals <= 6 and abs(value) < 1e9:
        return f"{value:.{decimals}f}"
    return f"{value:.6g}"  # very large or tiny numbers: "1.5e+12"


@dataclass(frozen=True)
class _Axis:
    """One axis: its data range, the ticks on it and their labels."""

    lo: float
    hi: float
    ticks: np.ndarray
    labels: list[str]


def _axis(lo: float, hi: float, length_px: int, min_gap_px: int) -> _Axis:
    """Ticks at a nice step, at least ``min_gap_px`` apart on an axis ``length_px`` long."""
    step = _nice_step((hi - lo) * min_gap_px / max(length_px - 1, 1))
    ticks = np.arange(math.ceil(lo / step - 1e-9), math.floor(hi / step + 1e-9) + 1) * step
    return _Axis(lo, hi, ticks, [_tick_label(float(t), step) for t in ticks])


def _x_axis(lo: float, hi: float, length_px: int, scale: int) -> _Axis:
    """Ticks far enough apart that their labels, written side by side, do not touch."""
    axis = _axis(lo, hi, length_px, 50 * scale)
    label_gap_px = (max(map(len, axis.labels), default=0) + 3) * _ADVANCE * scale
    if len(axis.ticks) > 1:
        tick_gap_px = (axis.ticks[1] - axis.ticks[0]) / (hi - lo) * (length_px - 1)
        if tick_gap_px < label_gap_px:
            axis = _axis(lo, hi, length_px, label_gap_px)
    return axis


def _widen(lo: float, hi: float, span: float) -> tuple[float, float]:
    """The range ``span`` wide with the same middle as (lo, hi)."""
    mid = (lo + hi) / 2
    return mid - span / 2, mid + span / 2


# --- layout ------------------------------------------------------------------------


@dataclass(frozen=True)
class _PlotArea:
    """Where the data goes: the pixel rectangle inside the frame and its two axes.

    Pixel centres: x.lo maps to column 0 and x.hi to column width - 1, y.hi to row 0.
    """

    left: int
    top: int
    width: int
    height: int
    x: _Axis
    y: _Axis

    def cols(self, x: np.ndarray) -> np.ndarray:
        """Data x to (fractional) columns relative to the plot area."""
        return (x - self.x.lo) * ((self.width - 1) / (self.x.hi - self.x.lo))

    def rows(self, y: np.ndarray) -> np.ndarray:
        """Data y to (fractional) rows relative to the plot area; up is row 0."""
        return (self.y.hi - y) * ((self.height - 1) / (self.y.hi - self.y.lo))


def _fit_plot_area(
    width_px: int,
    height_px: int,
    scale: int,
    xr: tuple[float, float],
    yr: tuple[float, float],
    equal_aspect: bool,
    *,
    title_h: int,
    has_x_label: bool,
    has_y_label: bool,
    legend_w: int,
) -> _PlotArea:
    """Place the plot area in the margins left for title, labels, ticks and legend."""
    pad, tick_len, line_h = 4 * scale, 3 * scale, _GLYPH_H * scale
    top = pad + (title_h + pad if title_h else 0) + 1
    bottom = 1 + tick_len + pad + line_h + ((pad + line_h) if has_x_label else 0) + pad
    right = 1 + pad + (legend_w + pad if legend_w else 3 * _ADVANCE * scale)
    height = height_px - top - bottom
    # The left margin holds the y tick labels, whose width depends on the y range,
    # which (equal_aspect) depends on the plot width: grow it until the labels fit.
    # This ends: labels_w only grows, and no tick label is longer than ~12 characters.
    labels_w = 0
    while True:
        left = pad + ((line_h + pad) if has_y_label else 0) + labels_w + pad + tick_len + 1
        width = width_px - left - right
        if width < 2 or height < 2:
            raise ValueError(f"a {width_px} x {height_px} chart leaves no room to plot")
        (x_lo, x_hi), (y_lo, y_hi) = xr, yr
        if equal_aspect:
            units_per_px = max((x_hi - x_lo) / (width - 1), (y_hi - y_lo) / (height - 1))
            x_lo, x_hi = _widen(x_lo, x_hi, units_per_px * (width - 1))
            y_lo, y_hi = _widen(y_lo, y_hi, units_per_px * (height - 1))
        y_axis = _axis(y_lo, y_hi, height, 30 * scale)
        needed = max((_text_width(t, scale) for t in y_axis.labels), default=0)
        if needed <= labels_w:
            return _PlotArea(left, top, width, height, _x_axis(x_lo, x_hi, width, scale), y_axis)
        labels_w = needed


# --- drawing -----------------------------------------------------------------------


def _draw_grid(img: np.ndarray, area: _PlotArea) -> None:
    """Light lines across the plot area at every tick."""
    plot = _plot_pixels(img, area)
    plot[:, np.rint(area.cols(area.x.ticks)).astype(int)] = _GRID
    plot[np.rint(area.rows(area.y.ticks)).astype(int), :] = _GRID


def _draw_frame_and_ticks(img: np.ndarray, area: _PlotArea, scale: int) -> None:
    """A one-pixel frame just outside the plot area, tick marks pointing outwards."""
    left, top = area.left - 1, area.top - 1
    right, bottom = area.left + area.width, area.top + area.height
    img[top, left : right + 1] = img[bottom, left : right + 1] = _INK
    img[top : bottom + 1, left] = img[top : bottom + 1, right] = _INK
    tick_len, pad = 3 * scale, 4 * scale
    for col, label in zip(area.left + np.rint(area.cols(area.x.ticks)).astype(int), area.x.labels):
        img[bottom + 1 : bottom + 1 + tick_len, col] = _INK
        label_left = col - _text_width(label, scale) // 2
        _draw_text(img, label, label_left, bottom + 1 + tick_len + pad, scale)
    for row, label in zip(area.top + np.rint(area.rows(area.y.ticks)).astype(int), area.y.labels):
        img[row, left - tick_len : left] = _INK
        x = left - tick_len - pad - _text_width(label, scale)
        _draw_text(img, label, x, row - _CAP_H * scale // 2, scale)


def _title_scale(title: str, width_px: int, scale: int) -> int:
    """The title's font scale: one up from the rest, unless that makes it too wide."""
    fits = _text_width(title, scale + 1) <= width_px - 8 * scale
    return scale + 1 if fits else scale


def _draw_titles(
    img: np.ndarray, area: _PlotArea, scale: int, title_scale: int, texts: tuple[str, str, str]
) -> None:
    """Title centred above the plot (but kept on the image), x label below the tick
    labels, y label turned to read upwards."""
    title, x_label, y_label = texts
    pad, line_h = 4 * scale, _GLYPH_H * scale
    centre_x, centre_y = area.left + area.width // 2, area.top + area.height // 2
    title_w = _text_width(title, title_scale)
    title_left = max(pad, min(centre_x - title_w // 2, img.shape[1] - pad - title_w))
    _draw_text(img, title, title_left, pad, title_scale)
    label_y = area.top + area.height + 1 + 3 * scale + pad + line_h + pad
    _draw_text(img, x_label, centre_x - _text_width(x_label, scale) // 2, label_y, scale)
    turned = np.rot90(_text_mask(y_label, scale))  # reads bottom to top
    _paint(img, turned, pad, centre_y - turned.shape[0] // 2, _INK)


def _legend_lines(series: Sequence[Series], width_px: int, scale: int) -> list[str]:
    """The labels as the legend shows them: cut with ".." so that the legend takes
    about a quarter of the chart width at most."""
    max_chars = max(4, width_px // 4 // (_ADVANCE * scale) - 6)
    cut = max_chars - 2
    return [s.label if len(s.label) <= max_chars else f"{s.label[:cut]}.." for s in series]


def _legend_width(lines: list[str], scale: int) -> int:
    """Pixel width of the legend box; 0 when there is no series."""
    if not lines:
        return 0
    pad, sample_w = 4 * scale, 6 * _ADVANCE * scale
    return pad + sample_w + pad + max(_text_width(t, scale) for t in lines) + pad


def _draw_legend(
    img: np.ndarray, area: _PlotArea, scale: int, lines: list[str], series: Sequence[Series]
) -> None:
    """A framed box right of the plot: per series a sample of its line, then its label."""
    if not lines:
        return
    pad, line_h = 4 * scale, (_GLYPH_H + 2) * scale
    left, top = area.left + area.width + 1 + pad, area.top - 1
    right = left + _legend_width(lines, scale)
    bottom = min(top + pad + len(lines) * line_h + pad, img.shape[0] - 1)
    img[top, left:right] = img[bottom, left:right] = _LEGEND_FRAME
    img[top : bottom + 1, left] = img[top : bottom + 1, right - 1] = _LEGEND_FRAME
    sample_w = 6 * _ADVANCE * scale
    for i, (label, s) in enumerate(zip(lines, series)):
        text_top = top + pad + i * line_h
        # a sample at least 2 px thick, so that thin lines' colours can be told apart,
        # and at most a capital letter high, so that thick ones do not hide the next row
        thickness = min(max(2, s.width_px), _CAP_H * scale)
        mid = text_top + _CAP_H * scale // 2 - thickness // 2
        img[mid : mid + thickness, left + pad : left + pad + sample_w] = s.color
        _draw_text(img, label, left + pad + sample_w + pad, text_top, scale)


def _plot_pixels(img: np.ndarray, area: _PlotArea) -> np.ndarray:
    """The view of ``img`` that is the plot area."""
    return img[area.top : area.top + area.height, area.left : area.left + area.width]


# --- polylines -----------------------------------------------------------------------

_BATCH_PX = 1 << 20  # pixels rasterised per numpy batch: bounds the temporary arrays


def _draw_polyline(
    img: np.ndarray, area: _PlotArea, x: np.ndarray, y: np.ndarray, color: RGB, width_px: int
) -> None:
    """Draw one series into the plot area, clipped to it."""
    cols, rows, stretch = _decimate(area.cols(x), area.rows(y), area.width)
    if cols.size == 0:  # nothing finite to draw
        return
    x0, y0, x1, y1 = _clip_segments(*_segments(cols, rows, stretch), area.width, area.height)
    mask = np.zeros((area.height, area.width), dtype=bool)
    _rasterise(mask, x0, y0, x1, y1)
    _plot_pixels(img, area)[_thicken(mask, width_px)] = color


def _decimate(
    cols: np.ndarray, rows: np.ndarray, width: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Drop the points that do not change which pixels the polyline covers.

    Consecutive points in one pixel column cover that column from their lowest to their
    highest point, so of each such run only the first, lowest, highest and last point
    are kept, in their order: a 100k-point series over ~1000 columns shrinks to ~4
    points per column, and peaks survive. Non-finite points are dropped; ``stretch``
    numbers the unbroken pieces, so that only points of one stretch get joined.
    """
    finite = np.isfinite(cols) & np.isfinite(rows)
    stretch = np.cumsum(~finite)[finite]  # a non-finite point starts a new stretch
    cols, rows = cols[finite], rows[finite]
    if cols.size == 0:
        return cols, rows, stretch
    # All columns left (right) of the plot are alike: lumping them into one keeps the
    # ints small, and the kept points' segments are clipped away just as the originals.
    column = np.clip(np.rint(cols), -2, width + 1)
    new_run = np.ones(cols.size, dtype=bool)
    new_run[1:] = (column[1:] != column[:-1]) | (stretch[1:] != stretch[:-1])
    starts = np.flatnonzero(new_run)
    ends = np.append(starts[1:], cols.size) - 1
    by_row = np.lexsort((rows, np.cumsum(new_run)))  # runs stay in place, sorted inside
    keep = np.sort(np.stack([starts, by_row[starts], by_row[ends], ends], axis=1), axis=1).ravel()
    keep = keep[np.append(True, keep[1:] != keep[:-1])]
    return cols[keep], rows[keep], stretch[keep]


def _segments(
    cols: np.ndarray, rows: np.ndarray, stretch: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Segments (x0, y0, x1, y1) between neighbours of one stretch; a point alone in
    its stretch becomes a zero-length segment, so that it shows as a dot."""
    joined = stretch[1:] == stretch[:-1]
    alone = ~np.append(False, joined) & ~np.append(joined, False)
    start = np.concatenate([np.flatnonzero(joined), np.flatnonzero(alone)])
    end = np.concatenate([np.flatnonzero(joined) + 1, np.flatnonzero(alone)])
    return cols[start], rows[start], cols[end], rows[end]


def _clip_segments(
    x0: np.ndarray, y0: np.ndarray, x1: np.ndarray, y1: np.ndarray, width: int, height: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Cut the segments to the plot area's pixels [-0.5, width - 0.5] x [-0.5, height - 0.5]
    (Liang-Barsky) and drop those entirely outside: far-off points cost no pixels."""
    dx, dy = x1 - x0, y1 - y0
    t_in, t_out = np.zeros_like(x0), np.ones_like(x0)
    keep = np.ones(x0.shape, dtype=bool)
    edges = ((-dx, x0 + 0.5), (dx, width - 0.5 - x0), (-dy, y0 + 0.5), (dy, height - 0.5 - y0))
    for p, q in edges:
        # the point at parameter t is inside this edge where p * t <= q
        with np.errstate(divide="ignore", invalid="ignore"):
            t = q / p
        t_in = np.where(p < 0, np.maximum(t_in, t), t_in)
        t_out = np.where(p > 0, np.minimum(t_out, t), t_out)
        keep &= (p != 0) | (q >= 0)  # parallel to the edge and outside it
    keep &= t_in <= t_out
    x0, y0, dx, dy, t_in, t_out = (a[keep] for a in (x0, y0, dx, dy, t_in, t_out))
    return x0 + t_in * dx, y0 + t_in * dy, x0 + t_out * dx, y0 + t_out * dy


def _rasterise(
    mask: np.ndarray, x0: np.ndarray, y0: np.ndarray, x1: np.ndarray, y1: np.ndarray
) -> None:
    """Set the pixels of each segment: a DDA that steps at most one pixel along both
    axes, so each line is 8-connected (Bresenham's pixels for pixel-centred ends)."""
    steps = np.ceil(np.maximum(np.abs(x1 - x0), np.abs(y1 - y0))).astype(np.int64)
    offsets = np.append(0, np.cumsum(steps + 1))  # segment i's pixels: offsets[i:i + 2]
    start = 0
    while start < steps.size:
        # the next batch: the segments whose pixels fit in _BATCH_PX (at least one)
        fit = int(np.searchsorted(offsets, offsets[start] + _BATCH_PX, side="right")) - 1
        stop = max(start + 1, fit)
        batch = slice(start, stop)
        _rasterise_batch(mask, x0[batch], y0[batch], x1[batch], y1[batch], steps[batch])
        start = stop


def _rasterise_batch(
    mask: np.ndarray,
    x0: np.ndarray,
    y0: np.ndarray,
    x1: np.ndarray,
    y1: np.ndarray,
    steps: np.ndarray,
) -> None:
    """``_rasterise`` for one batch: pixel k of a segment is its point at t = k / steps."""
    counts = steps + 1
    segment = np.repeat(np.arange(steps.size), counts)
    step = np.arange(segment.size) - np.repeat(np.cumsum(counts) - counts, counts)
    t = step / np.maximum(steps, 1)[segment]
    cols = np.rint(x0[segment] + t * (x1 - x0)[segment]).astype(np.int64)
    rows = np.rint(y0[segment] + t * (y1 - y0)[segment]).astype(np.int64)
    # clipping leaves ends on the area's outer pixel edges, which round one pixel out
    height, width = mask.shape
    mask[np.clip(rows, 0, height - 1), np.clip(cols, 0, width - 1)] = True


def _thicken(mask: np.ndarray, width_px: int) -> np.ndarray:
    """Widen one-pixel lines with a width_px x width_px square brush: OR of shifted
    copies, first along rows, then along columns."""
    offsets = range(-((width_px - 1) // 2), width_px // 2 + 1)
    for axis in (0, 1):
        wide = mask.copy()
        for d in offsets:
            if d:
                _or_shifted(wide, mask, d, axis)
        mask = wide
    return mask


def _or_shifted(out: np.ndarray, mask: np.ndarray, shift: int, axis: int) -> None:
    """out |= mask moved by ``shift`` pixels along ``axis`` (what moves off is lost)."""
    n = mask.shape[axis]
    dst = [slice(None), slice(None)]
    src = [slice(None), slice(None)]
    dst[axis] = slice(max(shift, 0), n + min(shift, 0))
    src[axis] = slice(max(-shift, 0), n + min(-shift, 0))
    out[tuple(dst)] |= mask[tuple(src)]


# --- text ------------------------------------------------------------------------------

# A 5 x 9 pixel font: rows top to bottom, "#" set. Capitals and digits use the top 7
# rows (the baseline is under row 7), descenders (g j p q y , _) the last 2.
_GLYPH_W, _GLYPH_H, _CAP_H = 5, 9, 7
_ADVANCE = _GLYPH_W + 1  # one blank column between glyphs
_FONT = {
    " ": "",
    "0": ".###. #...# #..## #.#.# ##..# #...# .###.",
    "1": "..#.. .##.. ..#.. ..#.. ..#.. ..#.. .###.",
    "2": ".###. #...# ....# ...#. ..#.. .#... #####",
    "3": "##### ...#. ..#.. ...#. ....# #...# .###.",
    "4": "...#. ..##. .#.#. #..#. ##### ...#. ...#.",
    "5": "##### #.... ####. ....# ....# #...# .###.",
    "6": "..##. .#... #.... ####. #...# #...# .###.",
    "7": "##### ....# ...#. ..#.. .#... .#... .#...",
    "8": ".###. #...# #...# .###. #...# #...# .###.",
    "9": ".###. #...# #...# .#### ....# ...#. .##..",
    "A": ".###. #...# #...# ##### #...# #...# #...#",
    "B": "####. #...# #...# ####. #...# #...# ####.",
    "C": ".###. #...# #.... #.... #.... #...# .###.",
    "D": "###.. #..#. #...# #...# #...# #..#. ###..",
    "E": "##### #.... #.... ####. #.... #.... #####",
    "F": "##### #.... #.... ####. #.... #.... #....",
    "G": ".###. #...# #.... #.### #...# #...# .####",
    "H": "#...# #...# #...# ##### #...# #...# #...#",
    "I": ".###. ..#.. ..#.. ..#.. ..#.. ..#.. .###.",
    "J": "..### ...#. ...#. ...#. ...#. #..#. .##..",
    "K": "#...# #..#. #.#.. ##... #.#.. #..#. #...#",
    "L": "#.... #.... #.... #.... #.... #.... #####",
    "M": "#...# ##.## #.#.# #.#.# #...# #...# #...#",
    "N": "#...# #...# ##..# #.#.# #..## #...# #...#",
    "O": ".###. #...# #...# #...# #...# #...# .###.",
    "P": "####. #...# #...# ####. #.... #.... #....",
    "Q": ".###. #...# #...# #...# #.#.# #..#. .##.#",
    "R": "####. #...# #...# ####. #.#.. #..#. #...#",
    "S": ".#### #.... #.... .###. ....# ....# ####.",
    "T": "##### ..#.. ..#.. ..#.. ..#.. ..#.. ..#..",
    "U": "#...# #...# #...# #...# #...# #...# .###.",
    "V": "#...# #...# #...# #...# #...# .#.#. ..#..",
    "W": "#...# #...# #...# #.#.# #.#.# #.#.# .#.#.",
    "X": "#...# #...# .#.#. ..#.. .#.#. #...# #...#",
    "Y": "#...# #...# .#.#. ..#.. ..#.. ..#.. ..#..",
    "Z": "##### ....# ...#. ..#.. .#... #.... #####",
    "a": "..... ..... .###. ....# .#### #...# .####",
    "b": "#.... #.... #.##. ##..# #...# #...# ####.",
    "c": "..... ..... .###. #.... #.... #...# .###.",
    "d": "....# ....# .##.# #..## #...# #...# .####",
    "e": "..... ..... .###. #...# ##### #.... .###.",
    "f": "..##. .#..# .#... ###.. .#... .#... .#...",
    "g": "..... ..... .#### #...# #...# #...# .#### ....# .###.",
    "h": "#.... #.... #.##. ##..# #...# #...# #...#",
    "i": "..#.. ..... .##.. ..#.. ..#.. ..#.. .###.",
    "j": "...#. ..... ..##. ...#. ...#. ...#. ...#. #..#. .##..",
    "k": "#.... #.... #..#. #.#.. ##... #.#.. #..#.",
    "l": ".##.. ..#.. ..#.. ..#.. ..#.. ..#.. .###.",
    "m": "..... ..... ##.#. #.#.# #.#.# #.#.# #.#.#",
    "n": "..... ..... #.##. ##..# #...# #...# #...#",
    "o": "..... ..... .###. #...# #...# #...# .###.",
    "p": "..... ..... ####. #...# #...# #...# ####. #.... #....",
    "q": "..... ..... .#### #...# #...# #...# .#### ....# ....#",
    "r": "..... ..... #.##. ##..# #.... #.... #....",
    "s": "..... ..... .###. #.... .###. ....# ####.",
    "t": ".#... .#... ###.. .#... .#... .#..# ..##.",
    "u": "..... ..... #...# #...# #...# #..## .##.#",
    "v": "..... ..... #...# #...# #...# .#.#. ..#..",
    "w": "..... ..... #...# #...# #.#.# #.#.# .#.#.",
    "x": "..... ..... #...# .#.#. ..#.. .#.#. #...#",
    "y": "..... ..... #...# #...# #...# #...# .#### ....# .###.",
    "z": "..... ..... ##### ...#. ..#.. .#... #####",
    ".": "..... ..... ..... ..... ..... .##.. .##..",
    ",": "..... ..... ..... ..... ..... .##.. .##.. ..#.. .#...",
    "-": "..... ..... ..... ##### ..... ..... .....",
    "+": "..... ..#.. ..#.. ##### ..#.. ..#.. .....",
    "/": "..... ....# ...#. ..#.. .#... #.... .....",
    "(": "...#. ..#.. .#... .#... .#... ..#.. ...#.",
    ")": ".#... ..#.. ...#. ...#. ...#. ..#.. .#...",
    "[": ".###. .#... .#... .#... .#... .#... .###.",
    "]": ".###. ...#. ...#. ...#. ...#. ...#. .###.",
    ":": "..... .##.. .##.. ..... .##.. .##.. .....",
    "%": "##... ##..# ...#. ..#.. .#... #..## ...##",
    "=": "..... ..... ##### ..... ##### ..... .....",
    "_": "..... ..... ..... ..... ..... ..... ..... #####",
    "^": "..#.. .#.#. #...# ..... ..... ..... .....",
    "*": "..... ..#.. #.#.# .###. #.#.# ..#.. .....",
    "<": "...#. ..#.. .#... #.... .#... ..#.. ...#.",
    ">": ".#... ..#.. ...#. ....# ...#. ..#.. .#...",
    "!": "..#.. ..#.. ..#.. ..#.. ..#.. ..... ..#..",
    "?": ".###. #...# ....# ...#. ..#.. ..... ..#..",
    "'": "..#.. ..#.. .#... ..... ..... ..... .....",
    "#": ".#.#. .#.#. ##### .#.#. ##### .#.#. .#.#.",
    "|": "..#.. ..#.. ..#.. ..#.. ..#.. ..#.. ..#..",
}
_UNKNOWN = "##### #...# #...# #...# #...# #...# #####"  # a box for characters not above


def _glyph(rows: str) -> np.ndarray:
    """A glyph's (_GLYPH_H, _ADVANCE) mask, its spacing column included."""
    mask = np.zeros((_GLYPH_H, _ADVANCE), dtype=bool)
    for r, row in enumerate(rows.split()):
        mask[r, : len(row)] = [c == "#" for c in row]
    return mask


_GLYPHS = {ch: _glyph(rows) for ch, rows in _FONT.items()}
_UNKNOWN_GLYPH = _glyph(_UNKNOWN)


def _text_width(text: str, scale: int) -> int:
    """Pixel width of ``text`` (no spacing after the last glyph)."""
    return max(0, len(text) * _ADVANCE - 1) * scale


def _text_mask(text: str, scale: int) -> np.ndarray:
    """``text`` as a boolean mask, _GLYPH_H * scale high, each font pixel scale x scale."""
    if not text:
        return np.zeros((_GLYPH_H * scale, 0), dtype=bool)
    mask = np.hstack([_GLYPHS.get(ch, _UNKNOWN_GLYPH) for ch in text])[:, :-1]
    return mask.repeat(scale, axis=0).repeat(scale, axis=1)


def _draw_text(img: np.ndarray, text: str, left: int, top: int, scale: int) -> None:
    """Write ``text`` in ink with its top-left corner (cap height) at (left, top)."""
    _paint(img, _text_mask(text, scale), left, top, _INK)


def _paint(img: np.ndarray, mask: np.ndarray, left: int, top: int, color: RGB) -> None:
    """Colour the pixels set in ``mask`` placed at (left, top); parts off the image are cut."""
    height, width = mask.shape
    r0, c0 = max(top, 0), max(left, 0)
    r1, c1 = min(top + height, img.shape[0]), min(left + width, img.shape[1])
    if r0 < r1 and c0 < c1:
        img[r0:r1, c0:c1][mask[r0 - top : r1 - top, c0 - left : c1 - left]] = color
