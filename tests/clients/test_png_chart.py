"""The PNG chart writer: the file format, and what lands on which pixel.

The charts are decoded again with the small PNG reader below (zlib, filter type 0 only)
and checked pixel by pixel: a line from the lower-left to the upper-right corner of the
data range must run from the lower-left to the upper-right corner of the plot frame.
"""

from __future__ import annotations

import struct
import time
import zlib

import numpy as np
import pytest

from cnc_objects.clients.png_chart import Series, _axis, encode_png, line_chart, write_line_chart

RED = (230, 20, 20)
BLUE = (20, 20, 230)
GREEN = (20, 160, 20)


def decode_png(data: bytes) -> np.ndarray:
    """The (H, W, 3) pixels of an 8-bit RGB PNG whose rows all use filter type 0;
    checks the signature, every chunk's CRC and the size of the decompressed data."""
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    pos, chunks = 8, []
    while pos < len(data):
        (length,) = struct.unpack(">I", data[pos : pos + 4])
        kind, payload = data[pos + 4 : pos + 8], data[pos + 8 : pos + 8 + length]
        (crc,) = struct.unpack(">I", data[pos + 8 + length : pos + 12 + length])
        assert crc == zlib.crc32(kind + payload), f"bad CRC in {kind!r}"
        chunks.append((kind, payload))
        pos += 12 + length
    assert pos == len(data)
    assert [k for k, _ in chunks][0] == b"IHDR" and chunks[-1] == (b"IEND", b"")
    width, height, depth, color_type, compression, filtering, interlace = struct.unpack(
        ">IIBBBBB", chunks[0][1]
    )
    assert (depth, color_type, compression, filtering, interlace) == (8, 2, 0, 0, 0)
    raw = zlib.decompress(b"".join(p for k, p in chunks if k == b"IDAT"))
    assert len(raw) == height * (1 + 3 * width)
    rows = np.frombuffer(raw, dtype=np.uint8).reshape(height, 1 + 3 * width)
    assert not rows[:, 0].any(), "only filter type 0 is expected"
    return rows[:, 1:].reshape(height, width, 3)


def render(series: list[Series], **kw: object) -> np.ndarray:
    kw = {"title": "Test", "x_label": "x [mm]", "y_label": "y [mm]", **kw}
    return decode_png(line_chart(series, **kw))  # type: ignore[arg-type]


def painted(img: np.ndarray, color: tuple[int, int, int]) -> np.ndarray:
    """Where ``img`` has exactly ``color``."""
    return (img == np.array(color, dtype=np.uint8)).all(axis=2)


def plot_interior(img: np.ndarray) -> tuple[int, int, int, int]:
    """(top, bottom, left, right), inclusive, of the pixels inside the black plot frame:
    the frame is the only black line longer than half the image."""
    black = painted(img, (0, 0, 0))
    rows = np.flatnonzero(black.sum(axis=1) > img.shape[1] / 2)
    cols = np.flatnonzero(black.sum(axis=0) > img.shape[0] / 2)
    assert len(rows) == 2 and len(cols) == 2, (rows, cols)
    return rows[0] + 1, rows[1] - 1, cols[0] + 1, cols[1] - 1


def test_png_file_structure() -> None:
    series = [Series("a", [0, 1], [0, 1], RED)]
    data = line_chart(series, title="t", x_label="x", y_label="y", width_px=321, height_px=207)
    img = decode_png(data)
    assert img.shape == (207, 321, 3)
    assert struct.unpack(">II", data[16:24]) == (321, 207)


def test_encode_png_round_trip() -> None:
    rgb = np.random.default_rng(7).integers(0, 256, size=(13, 29, 3), dtype=np.uint8)
    assert np.array_equal(decode_png(encode_png(rgb)), rgb)


def test_encode_png_rejects_other_arrays() -> None:
    with pytest.raises(ValueError):
        encode_png(np.zeros((4, 4, 3), dtype=np.float64))
    with pytest.raises(ValueError):
        encode_png(np.zeros((4, 4), dtype=np.uint8))


def test_diagonal_runs_corner_to_corner_of_the_frame() -> None:
    img = render([Series("diag", [0, 10], [0, 10], RED)], x_range=(0, 10), y_range=(0, 10))
    top, bottom, left, right = plot_interior(img)
    rows, cols = np.nonzero(painted(img[:, : right + 1], RED))  # not the legend
    assert (rows.min(), rows.max(), cols.min(), cols.max()) == (top, bottom, left, right)
    assert painted(img, RED)[bottom, left] and painted(img, RED)[top, right]
    # every column has a pixel, within a pixel of the ideal line
    assert set(cols) == set(range(left, right + 1))
    ideal = bottom - (cols - left) * (bottom - top) / (right - left)
    assert np.abs(rows - ideal).max() <= 1


def test_horizontal_and_vertical_lines_sit_at_their_values() -> None:
    img = render(
        # the horizontal line is drawn last, so it is on top where they cross
        [Series("v", [2.5, 2.5], [0, 10], BLUE), Series("h", [0, 10], [5, 5], RED)],
        x_range=(0, 10),
        y_range=(0, 10),
    )
    top, bottom, left, right = plot_interior(img)
    rows, cols = np.nonzero(painted(img[:, : right + 1], RED))
    assert len(set(rows)) == 1 and abs(rows[0] - (top + bottom) / 2) <= 0.5
    assert set(cols) == set(range(left, right + 1))
    rows, cols = np.nonzero(painted(img[:, : right + 1], BLUE))
    assert abs(cols.mean() - (left + (right - left) / 4)) <= 1 and np.ptp(cols) == 0
    assert (rows.min(), rows.max()) == (top, bottom)


def test_line_width_px() -> None:
    img = render([Series("h", [0, 10], [5, 5], RED, width_px=3)], x_range=(0, 10), y_range=(0, 10))
    _, _, left, right = plot_interior(img)
    rows = np.flatnonzero(painted(img[:, left + 10 : left + 11], RED)[:, 0])
    assert len(rows) == 3 and np.ptp(rows) == 2


def test_outside_the_range_is_clipped() -> None:
    big = [-1e12, -100, 1e12, np.inf]
    series = [
        Series("through", [-10, 20], [-10, 20], RED),  # the diagonal, extended both ways
        Series("far off", [-5, -1, 30, 1e9], big, BLUE),
        # parallel to an edge, just outside it: nothing to draw
        Series("above", [0, 10], [10.2, 10.2], GREEN),
        Series("right", [10.2, 10.2], [0, 10], GREEN),
    ]
    img = render(series, x_range=(0, 10), y_range=(0, 10))
    top, bottom, left, right = plot_interior(img)
    plot_and_left = img[:, : right + 2]  # everything but the legend
    inside = np.zeros(plot_and_left.shape[:2], dtype=bool)
    inside[top : bottom + 1, left : right + 1] = True
    for color in (RED, BLUE):
        assert not (painted(plot_and_left, color) & ~inside).any()
    rows, cols = np.nonzero(painted(plot_and_left, RED))
    assert (rows.min(), rows.max(), cols.min(), cols.max()) == (top, bottom, left, right)
    assert not painted(plot_and_left, GREEN).any()


def test_nan_breaks_the_line() -> None:
    x = np.arange(11.0)
    y = np.full(11, 5.0)
    y[5] = np.nan
    x_gap = np.arange(11.0)
    x_gap[2] = np.nan
    img = render(
        [Series("y gap", x, y, RED), Series("x gap", x_gap, np.full(11, 8.0), BLUE)],
        x_range=(0, 10),
        y_range=(0, 10),
    )
    top, bottom, left, right = plot_interior(img)
    scale = (right - left) / 10

    def drawn(color: tuple[int, int, int], x_value: float) -> bool:
        return bool(painted(img, color)[top : bottom + 1, left + round(x_value * scale)].any())

    # the red line ends at x = 4 and starts again at x = 6, the blue one at 1 and 3
    assert drawn(RED, 2) and drawn(RED, 4) and drawn(RED, 6) and drawn(RED, 8)
    assert not drawn(RED, 4.2) and not drawn(RED, 5) and not drawn(RED, 5.8)
    assert drawn(BLUE, 0.5) and drawn(BLUE, 1) and drawn(BLUE, 3) and drawn(BLUE, 3.5)
    assert not drawn(BLUE, 1.2) and not drawn(BLUE, 2) and not drawn(BLUE, 2.8)


def test_peaks_survive_100k_points() -> None:
    x = np.linspace(0, 1, 100_000)
    y = np.zeros_like(x)
    y[50_001] = 10.0  # one sample out of ~90 in its pixel column
    img = render([Series("spike", x, y, RED)], x_range=(0, 1), y_range=(0, 10))
    top, _, _, right = plot_interior(img)
    assert painted(img[:, : right + 1], RED)[top].any()


def test_equal_aspect_keeps_a_circle_round() -> None:
    angle = np.linspace(0, 2 * np.pi, 721)
    circle = [Series("circle", 3 + np.cos(angle), -2 + np.sin(angle), RED)]

    def extent(img: np.ndarray) -> tuple[int, int]:
        _, _, _, right = plot_interior(img)
        rows, cols = np.nonzero(painted(img[:, : right + 1], RED))
        return int(np.ptp(cols)), int(np.ptp(rows))

    width, height = extent(render(circle, equal_aspect=True))
    assert abs(width - height) <= 2 and height > 100
    width, height = extent(render(circle))  # without: stretched to the plot's shape
    assert width - height > 100


def test_equal_aspect_with_given_ranges() -> None:
    square = [Series("square", [0, 1, 1, 0, 0], [0, 0, 1, 1, 0], RED)]
    img = render(square, x_range=(0, 1), y_range=(0, 1), equal_aspect=True, width_px=900)
    _, _, _, right = plot_interior(img)
    rows, cols = np.nonzero(painted(img[:, : right + 1], RED))
    assert abs(np.ptp(cols) - np.ptp(rows)) <= 1


def test_title_renders() -> None:
    def dark_above_frame(title: str) -> int:
        img = render([Series("a", [0, 1], [0, 1], RED)], title=title)
        top, _, left, right = plot_interior(img)
        return int((img[: top - 1, left : right + 1].sum(axis=2) < 200).sum())

    assert dark_above_frame("") == 0
    assert dark_above_frame("Path speed over distance") > 200


REQUIRED_CHARS = (
    "0123456789ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz.,-+/():%=_^*"
)


def test_font_has_every_required_character() -> None:
    def title_pixels(title: str) -> bytes:
        img = render([], title=title, x_label="", y_label="", width_px=200, height_px=150)
        top, _, _, _ = plot_interior(img)
        return img[: top - 1].tobytes()

    blank, unknown = title_pixels(" "), title_pixels("\x7f")
    assert unknown != blank
    seen = set()
    for ch in REQUIRED_CHARS:
        pixels = title_pixels(ch)
        assert pixels not in (blank, unknown), f"{ch!r} has no glyph"
        seen.add(pixels)
    assert len(seen) == len(REQUIRED_CHARS), "two characters share a glyph"


def test_legend_shows_each_series_colour_right_of_the_plot() -> None:
    img = render([Series("first", [0, 1], [0, 1], RED), Series("second", [0, 1], [1, 0], BLUE)])
    _, _, _, right = plot_interior(img)
    for color in (RED, BLUE):
        assert painted(img[:, right + 2 :], color).sum() >= 20


@pytest.mark.parametrize(
    "series",
    [
        [],
        [Series("empty", [], [], RED)],
        [Series("all NaN", [np.nan] * 5, [np.nan] * 5, RED)],
        [Series("inf", [0, 1, 2], [np.inf, -np.inf, np.inf], RED)],
        [Series("constant", [1, 2, 3], [4, 4, 4], RED)],
        [Series("negative", [-3, -1], [-7, -2], RED)],
    ],
    ids=["none", "empty", "all-nan", "inf", "constant", "negative"],
)
def test_degenerate_data_still_draws_a_chart(series: list[Series]) -> None:
    img = render(series)
    top, bottom, left, right = plot_interior(img)
    assert bottom - top > 100 and right - left > 100


def test_a_lone_point_between_nans_is_a_dot() -> None:
    dot = Series("dot", [1, 2, 3], [np.nan, 5, np.nan], RED)
    img = render([dot], x_range=(0, 4), y_range=(0, 10))
    _, _, _, right = plot_interior(img)
    assert painted(img[:, : right + 1], RED).sum() == 1


def test_y_starts_at_zero_for_non_negative_data() -> None:
    img = render([Series("v", [0, 10], [100, 200], RED)])
    _, bottom, _, right = plot_interior(img)
    rows, _ = np.nonzero(painted(img[:, : right + 1], RED))
    # y = 100 is about half way up a 0..200 axis, not at the bottom
    assert rows.max() < bottom - 150


def test_nice_ticks() -> None:
    axis = _axis(0.0, 6180.0, 470, 60)
    assert list(axis.ticks) == [0, 1000, 2000, 3000, 4000, 5000, 6000]
    assert axis.labels == ["0", "1000", "2000", "3000", "4000", "5000", "6000"]
    axis = _axis(-0.13, 0.41, 500, 80)
    assert axis.labels == ["-0.1", "0.0", "0.1", "0.2", "0.3", "0.4"]
    axis = _axis(0.0, 250.0, 1000, 150)
    assert axis.labels == ["0", "50", "100", "150", "200", "250"]


def test_bad_input_is_refused() -> None:
    with pytest.raises(ValueError):
        Series("short", [0, 1, 2], [0, 1], RED)
    with pytest.raises(ValueError):
        Series("colour", [0], [0], (0, 0, 256))
    with pytest.raises(ValueError):
        render([], x_range=(1, 1))
    with pytest.raises(ValueError):
        render([], width_px=40, height_px=30)


def test_write_line_chart(tmp_path) -> None:
    path = tmp_path / "chart.png"
    write_line_chart(path, [Series("a", [0, 1], [0, 1], RED)], title="t", x_label="x", y_label="y")
    assert decode_png(path.read_bytes()).shape == (600, 1200, 3)


def test_three_series_of_100k_points_are_fast() -> None:
    s = np.linspace(0, 500, 100_000)
    rng = np.random.default_rng(3)
    series = [
        Series("optimum", s, 3000 + 2000 * np.sin(s / 7) ** 2, RED),
        Series("actual", s, 2900 + 2000 * np.sin(s / 7) ** 2 + rng.normal(0, 50, s.size), BLUE),
        Series("feed limit", s, np.where(s % 40 < 20, 6000.0, 4000.0), GREEN, 2),
    ]
    start = time.perf_counter()
    data = line_chart(series, title="speed", x_label="s [mm]", y_label="v [mm/min]")
    elapsed = time.perf_counter() - start
    assert elapsed < 5.0, f"{elapsed:.2f} s"
    assert painted(decode_png(data), BLUE).sum() > 1000
