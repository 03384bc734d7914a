"""Choosing the subject: a box the user gave, or the best candidate of a detector."""
from __future__ import annotations

import math
from collections import deque
from collections.abc import Sequence

from tracker.boxes import iou
from tracker.detectors import Detection

PICKS = ("central", "largest")
CAMERA_MOTION_FRACTION = 0.10  # motion over more of the frame than this: the camera moved


class StartConfirmer:
    """Starts on a detection only once it persists: seen (IoU >= ``min_iou``) in ``needed`` of the
    last ``window`` usable frames. With ``max_moving_fraction`` (for the motion detector) frames
    whose detections cover more of the image than that are skipped: the camera itself moved, so
    a static-camera motion detector says nothing about the subject there."""

    def __init__(self, needed: int = 3, window: int = 5, min_iou: float = 0.5,
                 max_moving_fraction: float | None = None) -> None:
        self.needed = needed
        self.min_iou = min_iou
        self.max_moving_fraction = max_moving_fraction
        self._recent: deque[Sequence[Detection]] = deque(maxlen=window - 1)

    def offer(self, detections: Sequence[Detection], frame_size: tuple[int, int]) -> list[Detection]:
        """This frame's detections that are confirmed (empty until one persists)."""
        width, height = frame_size
        covered = sum(d.box[2] * d.box[3] for d in detections) / float(width * height)
        if self.max_moving_fraction is not None and covered > self.max_moving_fraction:
            return []
        confirmed = [d for d in detections if 1 + sum(
            any(iou(d.box, seen.box) >= self.min_iou for seen in frame) for frame in self._recent
        ) >= self.needed]
        self._recent.append(list(detections))
        return confirmed

    def reset(self) -> None:
        """Forget what was seen: the next start must persist on its own."""
        self._recent.clear()


def pick_candidate(detections: Sequence[Detection], frame_size: tuple[int, int],
                   pick: str = "central") -> Detection | None:
    """The detection to start on: the most central or the largest one; None when there is none."""
    if not detections:
        return None
    if pick not in PICKS:
        raise ValueError(f"unknown pick {pick!r} (choose from {', '.join(PICKS)})")
    width, height = frame_size

    def distance(d: Detection) -> float:
        x, y, w, h = d.box
        return math.hypot(x + w / 2.0 - width / 2.0, y + h / 2.0 - height / 2.0)

    if pick == "largest":
        return max(detections, key=lambda d: d.box[2] * d.box[3])
    return min(detections, key=distance)


def parse_roi(text: str) -> tuple[int, int, int, int]:
    """``x,y,w,h`` in pixels -> a box; raises ValueError with a readable message."""
    parts = text.replace(" ", "").split(",")
    try:
        x, y, w, h = (int(float(p)) for p in parts)
    except (ValueError, OverflowError):  # OverflowError: inf (or 1e400) has no integer
        raise ValueError(f"--roi takes x,y,w,h in pixels, not {text!r}") from None
    if w <= 0 or h <= 0:
        raise ValueError(f"--roi {text!r}: w and h must be > 0")
    return x, y, w, h


def check_roi_in_frame(roi: tuple[int, int, int, int], size: tuple[int, int]) -> None:
    """Raise ValueError when less than half of ``roi`` lies inside the frame of ``size`` (w, h): a
    typo or another clip's coordinates (tracking a background patch would drive the gimbal). A box
    over an edge is fine as it is: the tracker follows the subject where it is, half out of view."""
    x, y, w, h = roi
    width, height = size
    x0, y0, x1, y1 = max(x, 0), max(y, 0), min(x + w, width), min(y + h, height)
    if x1 <= x0 or y1 <= y0 or (x1 - x0) * (y1 - y0) < 0.5 * w * h:
        raise ValueError(f"--roi {x},{y},{w},{h} lies {'outside' if x1 <= x0 or y1 <= y0 else 'mostly outside'} "
                         f"the {width}x{height} frame")
