"""Time-series plots drawn with matplotlib."""
from __future__ import annotations

import math
from pathlib import Path

import cv2
import numpy as np
import pytest

from pipelines.outputs.plot import PALETTE, _figure, render_timeseries, write_timeseries_png


def _colour_pixels(image: np.ndarray, colour: tuple[int, int, int]) -> int:
    return int(np.all(image == np.array(colour, np.uint8), axis=2).sum())


def test_png_has_the_requested_size(tmp_path: Path) -> None:
    t = np.arange(300) / 30
    path = tmp_path / "plot.png"
    write_timeseries_png(path, t, [{"yaw": np.sin(t), "pitch": np.cos(t)}, {"rate": t * 2}],
                         ["error", "rate"], ["deg", "deg/s"], width=800, panel_height=200)
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    image = cv2.imread(str(path))
    assert image.shape == (400, 800, 3)
    assert _colour_pixels(image, PALETTE[0]) > 200 and _colour_pixels(image, PALETTE[1]) > 200
    assert list(tmp_path.iterdir()) == [path]


def test_gaps_and_constant_series_are_drawn() -> None:
    t = list(range(10))
    values: list[float | None] = [1.0, 2.0, None, math.nan, 5.0, 6.0, 7.0, 8.0, 9.0, 10.0]
    with_gap = render_timeseries(t, [{"v": values}])
    without = render_timeseries(t, [{"v": [float(v) for v in range(1, 11)]}])
    assert _colour_pixels(with_gap, PALETTE[0]) < _colour_pixels(without, PALETTE[0])
    flat = render_timeseries(t, [{"flat": [3.0] * 10}, {"nothing": [None] * 10}])
    assert flat.shape == (480, 960, 3) and _colour_pixels(flat, PALETTE[0]) > 100


def test_line_follows_the_data() -> None:
    image = render_timeseries([0.0, 1.0], [{"up": [0.0, 1.0]}], width=400, panel_height=200)
    ys, xs = np.nonzero(np.all(image == np.array(PALETTE[0], np.uint8), axis=2))
    line = xs < 250  # leave out the legend sample in the top-right corner
    left, right = ys[line][xs[line] < xs[line].min() + 10], ys[line][xs[line] > 240]
    assert left.mean() > right.mean()  # rising line: y pixel decreases to the right


@pytest.mark.parametrize(("kwargs", "message"), [
    ({"t": [0, 1], "panels": []}, "at least one panel"),
    ({"t": [0, 1], "panels": [{"a": [1, 2, 3]}]}, "3 values for 2 times"),
    ({"t": [0, 1], "panels": [{"a": [1, 2]}], "titles": ["x", "y"]}, "1 panels but 2 titles"),
])
def test_bad_arguments(kwargs: dict, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        render_timeseries(**kwargs)


def test_axes_are_labelled_and_the_series_named() -> None:
    """What a reader needs on each panel: its title, the y unit, one legend entry per series, and
    the time axis named once under the bottom panel; ticks are matplotlib's own."""
    figure = _figure([0.0, 1.0, 2.0], [{"yaw": [0, 1, 2], "pitch": [2, 1, 0]}, {"rate": [1, 1, 1]}],
                     ["angular error", "commanded rates"], ["deg", "deg/s"], "time (s)", 960, 240)
    top, bottom = figure.axes
    assert (top.get_title(), top.get_ylabel(), bottom.get_title(), bottom.get_ylabel()) == \
        ("angular error", "deg", "commanded rates", "deg/s")
    assert [t.get_text() for t in top.get_legend().get_texts()] == ["yaw", "pitch"]
    assert [t.get_text() for t in bottom.get_legend().get_texts()] == ["rate"]
    assert bottom.get_xlabel() == "time (s)" and top.get_xlabel() == ""
    assert bottom.get_xlim() == (0.0, 2.0) and len(bottom.get_xticks()) >= 3
