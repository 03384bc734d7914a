"""The target estimate passed from the tracker to every later stage."""
from __future__ import annotations

from dataclasses import dataclass
from enum import Enum

from tracker.runtime.boxes import Box, center


class TrackState(str, Enum):
    """Where the tracker stands with its subject."""

    TRACKING = "tracking"  # subject followed with good confidence
    SEARCHING = "searching"  # confidence dropped; predicting and searching near the prediction
    LOST = "lost"  # subject gone; waiting for re-detection


@dataclass(frozen=True, slots=True)
class TargetEstimate:
    """One frame's estimate of the subject, in pixels of that frame.

    ``box`` is ``(x, y, w, h)`` with a top-left origin; ``velocity`` is the box centre's
    velocity in pixels per second; ``timestamp`` is the frame's capture time in seconds
    (the source's clock, monotonic within a run).
    """

    box: Box
    velocity: tuple[float, float]
    confidence: float
    state: TrackState
    timestamp: float
    frame_index: int

    @property
    def center(self) -> tuple[float, float]:
        return center(self.box)

    @property
    def found(self) -> bool:
        return self.state is TrackState.TRACKING
