"""Time-series line plots drawn with OpenCV (no plotting dependency): stacked panels sharing one time axis."""
from __future__ import annotations

import math
import os
from collections.abc import Mapping, Sequence

import cv2
import numpy as np

from pipelines.outputs._files import atomic_write

#: Line colours (BGR), used in order within a panel.
PALETTE = [(180, 119, 31), (14, 127, 255), (44, 160, 44), (40, 39, 214),
           (189, 103, 148), (75, 86, 140), (194, 119, 227), (127, 127, 127)]
_FONT = cv2.FONT_HERSHEY_SIMPLEX
_SCALE = 0.45
_BLACK, _GRID = (0, 0, 0), (225, 225, 225)
_MARGIN_LEFT, _MARGIN_RIGHT, _MARGIN_TOP, _MARGIN_BOTTOM = 78, 16, 28, 42


def nice_ticks(low: float, high: float, target: int = 5) -> list[float]:
    """About ``target`` round tick values (steps of 1, 2 or 5 × 10^k) within ``[low, high]``."""
    raw = (high - low) / max(target, 1)
    magnitude = 10.0 ** math.floor(math.log10(raw))
    step = next(m * magnitude for m in (1, 2, 5, 10) if m * magnitude >= raw)
    first = math.ceil(low / step - 1e-9)
    return [round((first + i) * step, 12) for i in range(int((high - low) / step + 1e-9) + 2)
            if (first + i) * step <= high + step * 1e-9]


def _tick_label(value: float, ticks: Sequence[float]) -> str:
    step = ticks[1] - ticks[0] if len(ticks) > 1 else 1.0
    decimals = max(0, -math.floor(math.log10(abs(step)) + 1e-9))
    return f"{value:.{decimals}f}"


def _limits(values: np.ndarray) -> tuple[float, float]:
    finite = values[np.isfinite(values)]
    if finite.size == 0:
        return -1.0, 1.0
    low, high = float(finite.min()), float(finite.max())
    pad = (high - low) * 0.05 if high > low else max(abs(high) * 0.1, 1.0)
    return low - pad, high + pad


def _text(canvas: np.ndarray, text: str, org: tuple[int, int], align: str = "left") -> None:
    (w, h), _ = cv2.getTextSize(text, _FONT, _SCALE, 1)
    x, y = org
    x -= {"left": 0, "centre": w // 2, "right": w}[align]
    cv2.putText(canvas, text, (x, y + h // 2), _FONT, _SCALE, _BLACK, 1, cv2.LINE_AA)


def _vertical_text(canvas: np.ndarray, text: str, centre: tuple[int, int]) -> None:
    (w, h), base = cv2.getTextSize(text, _FONT, _SCALE, 1)
    label = np.full((h + base + 2, w + 2, 3), 255, np.uint8)
    cv2.putText(label, text, (1, h + 1), _FONT, _SCALE, _BLACK, 1, cv2.LINE_AA)
    label = cv2.rotate(label, cv2.ROTATE_90_COUNTERCLOCKWISE)
    lh, lw = label.shape[:2]
    top = max(0, min(canvas.shape[0] - lh, centre[1] - lh // 2))
    left = max(0, centre[0] - lw // 2)
    region = canvas[top:top + lh, left:left + lw]
    region[:] = np.minimum(region, label[:region.shape[0], :region.shape[1]])


def _draw_legend(canvas: np.ndarray, names: Sequence[str], right: int, top: int) -> None:
    sizes = [cv2.getTextSize(name, _FONT, _SCALE, 1)[0] for name in names]
    row = max(h for _, h in sizes) + 8
    width = max(w for w, _ in sizes) + 40
    left = right - width - 6
    cv2.rectangle(canvas, (left, top + 6), (right - 6, top + 10 + row * len(names)), (255, 255, 255), cv2.FILLED)
    cv2.rectangle(canvas, (left, top + 6), (right - 6, top + 10 + row * len(names)), (160, 160, 160), 1)
    for i, name in enumerate(names):
        y = top + 8 + row * i + row // 2
        cv2.line(canvas, (left + 6, y), (left + 28, y), PALETTE[i % len(PALETTE)], 2, cv2.LINE_AA)
        _text(canvas, name, (left + 34, y))


def _draw_panel(canvas: np.ndarray, t: np.ndarray, series: Mapping[str, np.ndarray],
                title: str, ylabel: str, xlim: tuple[float, float], xlabel: str) -> None:
    height, width = canvas.shape[:2]
    left, right = _MARGIN_LEFT, width - _MARGIN_RIGHT
    top, bottom = _MARGIN_TOP, height - _MARGIN_BOTTOM
    ylim = _limits(np.concatenate(list(series.values()))) if series else (-1.0, 1.0)

    def px(x: np.ndarray) -> np.ndarray:
        return left + (x - xlim[0]) / (xlim[1] - xlim[0]) * (right - left)

    def py(y: np.ndarray) -> np.ndarray:
        return bottom - (y - ylim[0]) / (ylim[1] - ylim[0]) * (bottom - top)

    xticks, yticks = nice_ticks(*xlim, target=8), nice_ticks(*ylim, target=4)
    for value in xticks:
        x = round(float(px(np.float64(value))))
        cv2.line(canvas, (x, top), (x, bottom), _GRID, 1)
        cv2.line(canvas, (x, bottom), (x, bottom + 4), _BLACK, 1)
        _text(canvas, _tick_label(value, xticks), (x, bottom + 12), "centre")
    for value in yticks:
        y = round(float(py(np.float64(value))))
        cv2.line(canvas, (left, y), (right, y), _GRID, 1)
        cv2.line(canvas, (left - 4, y), (left, y), _BLACK, 1)
        _text(canvas, _tick_label(value, yticks), (left - 7, y), "right")
    for i, values in enumerate(series.values()):
        finite = np.isfinite(values) & np.isfinite(t)
        points = np.stack([px(t), py(values)], axis=1)
        # One polyline per run of finite samples, so gaps (NaN/None) stay gaps.
        for run in np.split(np.arange(len(t)), np.flatnonzero(np.diff(finite.astype(np.int8))) + 1):
            if finite[run[0]]:
                pts = np.round(points[run] * 16).astype(np.int32).reshape(-1, 1, 2)
                cv2.polylines(canvas, [pts], False, PALETTE[i % len(PALETTE)], 2, cv2.LINE_AA, shift=4)
    cv2.rectangle(canvas, (left, top), (right, bottom), _BLACK, 1)
    _text(canvas, title, ((left + right) // 2, top // 2), "centre")
    _text(canvas, xlabel, ((left + right) // 2, height - 12), "centre")
    _vertical_text(canvas, ylabel, (14, (top + bottom) // 2))
    if series:
        _draw_legend(canvas, list(series), right, top)


def render_timeseries(t: Sequence[float], panels: Sequence[Mapping[str, Sequence[float | None]]],
                      titles: Sequence[str] | None = None, ylabels: Sequence[str] | None = None, *,
                      xlabel: str = "time (s)", width: int = 960, panel_height: int = 240) -> np.ndarray:
    """The plot as a BGR image of ``width`` × ``panel_height * len(panels)`` pixels.

    Each panel maps a legend name to values aligned with ``t``; ``None``/NaN values leave gaps.
    """
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
        arrays.append({name: np.asarray(values, dtype=float) for name, values in panel.items()})
        for name, values in arrays[-1].items():
            if values.shape != times.shape:
                raise ValueError(f"series {name!r} has {values.size} values for {times.size} times")
    xlim = _limits(times)
    finite_t = times[np.isfinite(times)]
    if finite_t.size and finite_t.max() > finite_t.min():
        xlim = (float(finite_t.min()), float(finite_t.max()))
    image = np.full((panel_height * len(panels), width, 3), 255, np.uint8)
    for k, series in enumerate(arrays):
        _draw_panel(image[k * panel_height:(k + 1) * panel_height], times, series,
                    titles[k] if titles else "", ylabels[k] if ylabels else "", xlim, xlabel)
    return image


def write_timeseries_png(path: str | os.PathLike[str], t: Sequence[float],
                         panels: Sequence[Mapping[str, Sequence[float | None]]],
                         titles: Sequence[str] | None = None, ylabels: Sequence[str] | None = None,
                         **options: object) -> None:
    """Render (see ``render_timeseries``; ``options`` are its keyword options) and write a PNG atomically."""
    ok, png = cv2.imencode(".png", render_timeseries(t, panels, titles, ylabels, **options))
    if not ok:
        raise OSError(f"cannot encode plot {path}")
    atomic_write(path, png.tobytes())
