"""A frame that is not grey, BGR or BGRA uint8 is a ValueError naming it, from every tracker and
detector, rather than an OpenCV error or a frame tracked as something else (KCF and MOSSE took
float32 frames as they were)."""
from __future__ import annotations

import numpy as np
import pytest

from tracker.detectors import make_detector
from tracker.runtime.registry import make_tracker

BGR = np.random.default_rng(3).integers(0, 255, (120, 160, 3), dtype=np.uint8)
BAD = {"float32": BGR.astype(np.float32), "uint16": BGR.astype(np.uint16), "two channels": BGR[:, :, :2],
       "a list": BGR.tolist(), "None": None, "one row": BGR[0, :, 0]}
BOX = (60.0, 40.0, 30.0, 30.0)


@pytest.mark.parametrize("what", BAD)
@pytest.mark.parametrize("name", ["default", "kcf", "mosse", "csrt"])
def test_init_and_update_refuse_the_frame(name: str, what: str) -> None:
    with pytest.raises(ValueError, match="a frame must be"):
        make_tracker(name).init(BAD[what], BOX, 0.0)
    tracker = make_tracker(name)
    tracker.init(BGR, BOX, 0.0)
    with pytest.raises(ValueError, match="a frame must be"):
        tracker.update(BAD[what], 0.04)


@pytest.mark.parametrize("what", BAD)
@pytest.mark.parametrize("kind", ["face", "person", "motion"])
def test_detectors_refuse_the_frame(kind: str, what: str) -> None:
    with pytest.raises(ValueError, match="a frame must be"):
        make_detector(kind).detect(BAD[what])
