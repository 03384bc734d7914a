"""Choosing the subject: a box the user gave, or the best candidate of a detector."""
from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

from tracker.runtime.boxes import Box, center, iou

if TYPE_CHECKING:  # the tracker and detectors load OpenCV and SciPy: only a run needs them
    import numpy as np

    from pipelines.sources.base import Frame
    from tracker.detectors import Detection, Detector
    from tracker.runtime.estimate import TargetEstimate
    from tracker.runtime.subject import SubjectTracker

PICKS = ("central", "largest")
CAMERA_MOTION_FRACTION = 0.10  # motion over more of the frame than this: the camera moved


@dataclass
class _Candidate:
    """A detection seen before: its last box, the frame of that sighting, its velocity (box
    centre px per frame, None until seen twice) and the usable frames it was seen in."""

    box: Box
    frame: int
    velocity: tuple[float, float] | None
    seen: list[int]

    def predicted(self, frame: int) -> Box:
        """The last box moved on at the candidate's velocity to ``frame`` (held when unknown)."""
        vx, vy = self.velocity or (0.0, 0.0)
        x, y, w, h = self.box
        return (x + vx * (frame - self.frame), y + vy * (frame - self.frame), w, h)

    def see(self, box: Box, frame: int, usable: int) -> None:
        """Seen again at ``box`` in ``frame`` (the ``usable``-th frame not skipped)."""
        (cx, cy), (px, py) = center(box), center(self.box)
        self.velocity = ((cx - px) / (frame - self.frame), (cy - py) / (frame - self.frame))
        self.box, self.frame = box, frame
        self.seen.append(usable)


class StartConfirmer:
    """Starts on a detection only once it persists: a candidate seen in ``needed`` of the last
    ``window`` usable frames. A candidate keeps its last box and velocity (its last step), and a
    detection is its next sighting when it overlaps (IoU >= ``min_iou``) that box where it was or
    moved on at that velocity, so a subject crossing the picture is confirmed as soon as a still
    one (comparing raw boxes, one moving a sixth of its width a frame or more was late). A candidate
    seen once has no velocity yet: its next sighting is one that overlaps it so or, in the very
    next frame, one of about its size (areas within ``max_area_ratio``) whose centre is at most
    ``reach`` box sides (square root of its area) away. Detections at random places seldom fall
    on one line three times: flicker is not confirmed.
    With ``max_moving_fraction`` (for the motion detector) frames whose detections cover more of
    the image than that are skipped: the camera itself moved, so a static-camera motion detector
    says nothing about the subject there."""

    def __init__(self, needed: int = 3, window: int = 5, min_iou: float = 0.5,
                 max_moving_fraction: float | None = None, reach: float = 0.5,
                 max_area_ratio: float = 2.0) -> None:
        self.needed = needed
        self.window = window
        self.min_iou = min_iou
        self.max_moving_fraction = max_moving_fraction
        self.reach = reach
        self.max_area_ratio = max_area_ratio
        self._candidates: list[_Candidate] = []
        self._frame = -1  # every frame offered: the time a candidate moves in
        self._usable = -1  # frames not skipped: the window counts these

    def offer(self, detections: Sequence[Detection], frame_size: tuple[int, int]) -> list[Detection]:
        """This frame's detections that are confirmed (empty until one persists)."""
        self._frame += 1
        width, height = frame_size
        covered = sum(d.box[2] * d.box[3] for d in detections) / float(width * height)
        if self.max_moving_fraction is not None and covered > self.max_moving_fraction:
            return []
        self._usable += 1
        oldest = self._usable - self.window + 1
        self._candidates = [c for c in self._candidates if c.seen[-1] >= oldest]
        free = list(detections)
        confirmed = []
        for candidate in sorted(self._candidates, key=lambda c: -len(c.seen)):
            found = self._next_sighting(candidate, free)
            if found is None:
                continue
            free.remove(found)
            candidate.see(found.box, self._frame, self._usable)
            if sum(seen >= oldest for seen in candidate.seen) >= self.needed:
                confirmed.append(found)
        self._candidates += [_Candidate(d.box, self._frame, None, [self._usable]) for d in free]
        return [d for d in detections if any(d is c for c in confirmed)]

    def _next_sighting(self, candidate: _Candidate, detections: Sequence[Detection]) -> Detection | None:
        """The detection that continues ``candidate`` this frame, or None: the one overlapping its
        last box or its predicted box the most, else (seen once, in the frame before) the nearest
        one within reach."""
        predicted = candidate.predicted(self._frame)
        overlap = {id(d): max(iou(d.box, predicted), iou(d.box, candidate.box)) for d in detections}
        near = [d for d in detections if overlap[id(d)] >= self.min_iou]
        if near:
            return max(near, key=lambda d: overlap[id(d)])
        if candidate.velocity is not None or self._frame - candidate.frame > 1:
            return None
        sx, sy = center(candidate.box)
        reachable = [d for d in detections if self._within_reach(candidate.box, d.box)]
        return min(reachable, key=lambda d: math.hypot(center(d.box)[0] - sx, center(d.box)[1] - sy), default=None)

    def _within_reach(self, seen: Box, box: Box) -> bool:
        """``box`` is of about the size of ``seen`` and its centre at most ``reach`` sides away."""
        area, seen_area = box[2] * box[3], seen[2] * seen[3]
        if not seen_area / self.max_area_ratio <= area <= seen_area * self.max_area_ratio:
            return False
        (cx, cy), (sx, sy) = center(box), center(seen)
        return math.hypot(cx - sx, cy - sy) <= self.reach * math.sqrt(seen_area)


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


class AcquiringSubject:
    """The subject of a ``track`` run (a ``pipelines.loop.Subject``): none until a start box comes
    (the user's ``--roi``, an operator's, or a confirmed detection by the ``pick`` rule, looked for
    on every frame while none is chosen: the motion detector needs consecutive frames), then the
    tracker. A lost subject is found again by the tracker, which runs ``detector`` itself: a
    detection that looks like it, never merely the nearest one, so the subject's look is kept and
    another person's is not taken for it.

    With ``video_time`` (a file read faster than it was filmed, its frames stamped as they are read)
    the tracker's motion model runs on each frame's time in the video, not on how fast this machine
    reads it, so a run gives the same boxes every time; the estimates still carry the loop's time,
    which control uses."""

    def __init__(self, tracker: SubjectTracker, detector: Detector | None, frame_size: tuple[int, int], *,
                 roi: Box | None = None, pick: str = "central", confirmer: StartConfirmer | None = None,
                 video_time: bool = False) -> None:
        self.tracker = tracker
        self.detector = detector
        self.frame_size = frame_size
        self.pick = pick
        self.confirmer = confirmer or StartConfirmer()
        self.candidates: tuple[Detection, ...] = ()
        self.video_time = video_time
        self._start: Box | None = roi
        self._estimate: TargetEstimate | None = None

    @property
    def name(self) -> str:
        return self.tracker.name

    def start(self, box: Box) -> None:
        """Start the tracker afresh on ``box`` at the next frame."""
        self._start = tuple(box)

    def estimate(self, frame: Frame, t: float) -> TargetEstimate | None:
        self.candidates = ()
        if self._start is None and self._estimate is None:
            self._start = self._detect(frame.image)
            if self._start is None:
                return None
        tracker_t = frame.timestamp if self.video_time else t
        if self._start is not None:
            box, self._start = self._start, None
            self._estimate = self.tracker.init(frame.image, box, tracker_t)
        else:
            self._estimate = self.tracker.update(frame.image, tracker_t)
        if self.video_time:
            self._estimate = replace(self._estimate, timestamp=t)
        return self._estimate

    def _detect(self, image: np.ndarray) -> Box | None:
        """A confirmed detection to start on, by the pick rule."""
        if self.detector is None:
            return None
        self.candidates = tuple(self.detector.detect(image))
        confirmed = self.confirmer.offer(self.candidates, self.frame_size)
        found = pick_candidate(confirmed, self.frame_size, self.pick)
        return None if found is None else tuple(found.box)
