"""Axis-aligned boxes ``(x, y, w, h)`` in pixels, top-left origin."""
from __future__ import annotations

import math

import numpy as np

Box = tuple[float, float, float, float]


def center(box: Box) -> tuple[float, float]:
    """The box centre."""
    x, y, w, h = box
    return (x + w / 2.0, y + h / 2.0)


def from_center(cx: float, cy: float, w: float, h: float) -> Box:
    """The box of size ``w`` x ``h`` centred on ``(cx, cy)``."""
    return (cx - w / 2.0, cy - h / 2.0, w, h)


def iou(a: Box, b: Box) -> float:
    """Intersection over union of two boxes (0 when either is empty)."""
    ax, ay, aw, ah = a
    bx, by, bw, bh = b
    iw = min(ax + aw, bx + bw) - max(ax, bx)
    ih = min(ay + ah, by + bh) - max(ay, by)
    if iw <= 0 or ih <= 0:
        return 0.0
    inter = iw * ih
    union = aw * ah + bw * bh - inter
    return float(inter / union) if union > 0 else 0.0


def start_box(box: Box, width: int, height: int, min_size: float = 4.0) -> Box:
    """A subject's first box as given, grown about its centre to at least ``min_size`` a side.
    It may reach over the frame's edges (so may the subject: moving it inside would start the
    tracker on an offset patch); raises ``ValueError`` when it is not finite, has no width or
    height, or misses the frame."""
    if not all(math.isfinite(v) for v in box):
        raise ValueError(f"the start box {box} is not finite")
    if box[2] <= 0 or box[3] <= 0:
        raise ValueError(f"the start box {tuple(round(v, 1) for v in box)} needs a width and height above 0 "
                         "(x, y, w, h)")
    cx, cy = center(box)
    w, h = max(box[2], min_size), max(box[3], min_size)
    x, y = cx - w / 2.0, cy - h / 2.0
    if x >= width or y >= height or x + w <= 0 or y + h <= 0:
        raise ValueError(f"the start box {tuple(round(v, 1) for v in box)} lies outside the {width}x{height} frame")
    return (x, y, w, h)


def cut_to_frame(box: Box, width: int, height: int, min_size: float = 4.0) -> Box:
    """The part of ``box`` inside a ``width`` x ``height`` frame (for trackers that need their
    box inside), kept at least ``min_size`` a side within the frame."""
    x, y, w, h = box
    x0, y0 = max(x, 0.0), max(y, 0.0)
    x1, y1 = min(x + w, float(width)), min(y + h, float(height))
    return clip_to_frame((x0, y0, max(x1 - x0, 0.0), max(y1 - y0, 0.0)), width, height, min_size)


def clip_to_frame(box: Box, width: int, height: int, min_size: float = 4.0) -> Box:
    """The box kept inside a ``width`` x ``height`` frame, at least ``min_size`` on each side."""
    x, y, w, h = box
    w = float(np.clip(w, min_size, width))
    h = float(np.clip(h, min_size, height))
    x = float(np.clip(x, 0.0, width - w))
    y = float(np.clip(y, 0.0, height - h))
    return (x, y, w, h)


def polygon_to_box(points: list[float]) -> Box:
    """The axis-aligned min/max box around a flat ``x1, y1, x2, y2, ...`` polygon."""
    xs, ys = points[0::2], points[1::2]
    x0, y0 = min(xs), min(ys)
    return (x0, y0, max(xs) - x0, max(ys) - y0)
