"""Time-series line plots drawn with matplotlib (Agg, no display): stacked panels sharing one time axis."""
from __future__ import annotations

import io
import os
from collections.abc import Mapping, Sequence

import numpy as np

from pipelines.outputs._files import atomic_write

#: Line colours (BGR, as OpenCV and the returned image use them), in order within a panel:
#: matplotlib's default cycle.
PALETTE = [(180, 119, 31), (14, 127, 255), (44, 160, 44), (40, 39, 214),
           (189, 103, 148), (75, 86, 140), (194, 119, 227), (127, 127, 127)]
DPI = 100


def _rgb(bgr: tuple[int, int, int]) -> tuple[float, float, float]:
    b, g, r = bgr
    return r / 255.0, g / 255.0, b / 255.0


def _figure(t: Sequence[float], panels: Sequence[Mapping[str, Sequence[float | None]]],
            titles: Sequence[str] | None, ylabels: Sequence[str] | None, xlabel: str,
            width: int, panel_height: int):  # -> matplotlib.figure.Figure
    """The plot as a matplotlib figure of ``width`` x ``panel_height * len(panels)`` pixels."""
    from matplotlib.figure import Figure  # noqa: PLC0415 (matplotlib loads only when a plot is drawn)

    if not panels:
        raise ValueError("at least one panel is needed")
    for name, labels in (("titles", titles), ("ylabels", ylabels)):
        if labels is not None and len(labels) != len(panels):
            raise ValueError(f"{len(panels)} panels but {len(labels)} {name}")
    if width < 200 or panel_height < 120:
        raise ValueError("plot too small: width >= 200 and panel_height >= 120 pixels")
    times = np.asarray(t, dtype=float)
    arrays = []
    for panel in panels:
        arrays.append({name: np.asarray([np.nan if v is None else v for v in values], dtype=float)
                       for name, values in panel.items()})
        for name, values in arrays[-1].items():
            if values.shape != times.shape:
                raise ValueError(f"series {name!r} has {values.size} values for {times.size} times")
    figure = Figure(figsize=(width / DPI, panel_height * len(panels) / DPI), dpi=DPI, layout="constrained")
    axes = figure.subplots(len(panels), 1, sharex=True, squeeze=False)[:, 0]
    for k, (ax, series) in enumerate(zip(axes, arrays)):
        for i, (name, values) in enumerate(series.items()):
            ax.plot(times, values, color=_rgb(PALETTE[i % len(PALETTE)]), linewidth=2.0, label=name)
        ax.set_title(titles[k] if titles else "", fontsize=10)
        ax.set_ylabel(ylabels[k] if ylabels else "")
        ax.grid(True, color="0.88")
        if series:
            ax.legend(loc="upper left", bbox_to_anchor=(1.0, 1.0), fontsize=9, frameon=False)  # off the lines
    finite = times[np.isfinite(times)]
    if finite.size and finite.max() > finite.min():
        axes[-1].set_xlim(float(finite.min()), float(finite.max()))
    axes[-1].set_xlabel(xlabel)
    return figure


def render_timeseries(t: Sequence[float], panels: Sequence[Mapping[str, Sequence[float | None]]],
                      titles: Sequence[str] | None = None, ylabels: Sequence[str] | None = None, *,
                      xlabel: str = "time (s)", width: int = 960, panel_height: int = 240) -> np.ndarray:
    """The plot as a BGR image of ``width`` x ``panel_height * len(panels)`` pixels.

    Each panel maps a legend name to values aligned with ``t``; ``None``/NaN values leave gaps.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg  # noqa: PLC0415

    canvas = FigureCanvasAgg(_figure(t, panels, titles, ylabels, xlabel, width, panel_height))
    canvas.draw()
    rgba = np.asarray(canvas.buffer_rgba())
    return np.ascontiguousarray(rgba[:, :, 2::-1])


def write_timeseries_png(path: str | os.PathLike[str], t: Sequence[float],
                         panels: Sequence[Mapping[str, Sequence[float | None]]],
                         titles: Sequence[str] | None = None, ylabels: Sequence[str] | None = None, *,
                         xlabel: str = "time (s)", width: int = 960, panel_height: int = 240) -> None:
    """Draw (see ``render_timeseries``) and write a PNG atomically."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg  # noqa: PLC0415

    figure = _figure(t, panels, titles, ylabels, xlabel, width, panel_height)
    png = io.BytesIO()
    FigureCanvasAgg(figure).print_png(png)
    atomic_write(path, png.getvalue())
