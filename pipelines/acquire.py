"""Choosing the subject: a box the user gave, or the best candidate of a detector."""
from __future__ import annotations

import math
from collections.abc import Sequence

from tracker.detectors import Detection

PICKS = ("central", "largest")


def pick_candidate(detections: Sequence[Detection], frame_size: tuple[int, int],
                   pick: str = "central", near: tuple[float, float] | None = None) -> Detection | None:
    """The detection to follow: nearest ``near`` when given (re-acquisition), else the most
    central or the largest one; None when there is none."""
    if not detections:
        return None
    if pick not in PICKS:
        raise ValueError(f"unknown pick {pick!r} (choose from {', '.join(PICKS)})")
    width, height = frame_size
    target = near if near is not None else (width / 2.0, height / 2.0)

    def distance(d: Detection) -> float:
        x, y, w, h = d.box
        return math.hypot(x + w / 2.0 - target[0], y + h / 2.0 - target[1])

    if near is None and pick == "largest":
        return max(detections, key=lambda d: d.box[2] * d.box[3])
    return min(detections, key=distance)


def parse_roi(text: str) -> tuple[int, int, int, int]:
    """``x,y,w,h`` in pixels -> a box; raises ValueError with a readable message."""
    parts = text.replace(" ", "").split(",")
    try:
        x, y, w, h = (int(float(p)) for p in parts)
    except ValueError:
        raise ValueError(f"--roi takes x,y,w,h in pixels, not {text!r}") from None
    if w <= 0 or h <= 0 or x < 0 or y < 0:
        raise ValueError(f"--roi {text!r}: x and y must be >= 0, w and h > 0")
    return x, y, w, h
