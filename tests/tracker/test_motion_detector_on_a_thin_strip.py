"""A frame only a pixel or two high once worked on (a wide strip: 1000 x 2 shrinks to 640 x 1):
the camera-motion fit, which halves images over 400 px, cannot halve it and must not fail."""
from __future__ import annotations

import numpy as np
import pytest

from tracker.detectors.camera_motion import camera_motion
from tracker.detectors import MotionDetector


@pytest.mark.parametrize("shape", [(1, 1000, 3), (2, 1000, 3), (1000, 1, 3)])
def test_the_motion_detector_takes_a_thin_strip(shape: tuple[int, int, int]) -> None:
    rng = np.random.default_rng(0)
    detector = MotionDetector()
    for _ in range(4):  # a still camera worked on these before the camera-motion fit came
        assert isinstance(detector.detect(rng.integers(0, 256, shape, dtype=np.uint8)), list)


def test_a_one_pixel_high_image_gives_no_camera_motion() -> None:
    strip = np.random.default_rng(1).integers(0, 256, (1, 401), dtype=np.uint8)
    assert camera_motion(strip, np.roll(strip, 3, axis=1)) is None
