"""The look-ahead benchmark's speed plot (docs/lookahead-*.png): what the figure shows and
the command that writes it."""

from __future__ import annotations

import re
from pathlib import Path

from PIL import Image

from bench.lookahead_bench import TARGET, main, speed_figure
from bench.lookahead_programs import circle_chords


def test_the_figure_compares_both_runs_with_the_optimum() -> None:
    fig = speed_figure(circle_chords(1.0))
    [ax] = fig.axes
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("path distance (mm)", "path speed (mm/s)")
    assert ax.get_title() == "circle_chords_r1: path speed over path distance"
    [legend] = fig.legends
    labels = [t.get_text() for t in legend.get_texts()]
    assert labels[0] == "optimum" and labels[3] == "programmed feed F6000"
    ratios = {}
    for label in labels[1:3]:
        found = re.fullmatch(r"(LA_ON/120|LA_OFF/30): (\d\.\d{4}) x optimum time", label)
        assert found, label
        ratios[found.group(1)] = float(found.group(2))
    # 30 blocks of 1 um hold the path far below F; LA_ON follows the optimum
    assert ratios["LA_ON/120"] <= TARGET and ratios["LA_OFF/30"] > 2.0
    optimum, la_on, la_off, feed = ax.get_lines()
    assert set(feed.get_ydata()) == {100.0}  # F6000 in mm/s
    assert max(la_on.get_ydata()) <= 100.0 + 1e-9 and max(la_off.get_ydata()) < 20.0


def test_plot_only_writes_the_png(tmp_path: Path) -> None:
    target = tmp_path / "chords.png"
    assert main(["--quick", "--plot-only", "--plot", str(target),
                 "--plot-program", "circle_chords_r1"]) == 0
    with Image.open(target) as image:
        assert (image.format, image.size) == ("PNG", (1200, 600))
