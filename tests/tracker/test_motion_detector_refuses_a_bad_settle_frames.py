"""``MotionDetector(settle_frames=...)`` takes 1..255 (a pixel's age is counted in a byte)."""
from __future__ import annotations

import pytest

from tracker.detectors import MotionDetector


@pytest.mark.parametrize("frames", [0, 256])
def test_settle_frames_out_of_range_is_refused(frames: int) -> None:
    with pytest.raises(ValueError, match="settle_frames must be 1..255"):
        MotionDetector(settle_frames=frames)


@pytest.mark.parametrize("frames", [1, 255])
def test_settle_frames_at_the_ends_of_the_range_is_taken(frames: int) -> None:
    MotionDetector(settle_frames=frames)
