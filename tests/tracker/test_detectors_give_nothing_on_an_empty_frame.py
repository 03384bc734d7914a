"""An empty frame (no pixels) gives no candidates, for the motion and face detectors as for the
person detector (whose case runs in a child process in test_detectors.py)."""
from __future__ import annotations

import numpy as np
import pytest

from tracker.detectors import make_detector


@pytest.mark.parametrize("kind", ["motion", "face"])
@pytest.mark.parametrize("shape", [(0, 0, 3), (0, 5), (5, 0, 4)])
def test_an_empty_frame_gives_nothing(kind: str, shape: tuple[int, ...]) -> None:
    assert make_detector(kind).detect(np.zeros(shape, np.uint8)) == []
