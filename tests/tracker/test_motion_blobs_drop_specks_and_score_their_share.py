"""The motion detector's blobs: a moving speck smaller than ``min_area_fraction`` of the picture is
not a candidate, and each blob's score is its share of the moving area."""
from __future__ import annotations

import numpy as np
import pytest

from tracker.detectors import Detection, make_detector
from tracker.evaluation.synthetic import texture

RNG = np.random.default_rng(12)
BIG, SMALL = texture(40, 40, RNG, cell=5, contrast=1.0), texture(20, 20, RNG, cell=4, contrast=1.0)


def _last_detections(speck: int = 0) -> list[Detection]:
    """What a motion detector reports on the fourth frame of a grey scene where a 40 px square moves
    12 px a frame, with either a 20 px square or (``speck`` > 0) a white speck of that side moving too."""
    detector = make_detector("motion")
    found: list[Detection] = []
    for i in range(4):
        frame = np.full((240, 320, 3), 128, np.uint8)
        frame[100:140, 40 + 12 * i:80 + 12 * i] = BIG
        if speck:
            frame[20 + 6 * i:20 + 6 * i + speck, 250:250 + speck] = 255
        else:
            frame[180:200, 200 + 10 * i:220 + 10 * i] = SMALL
        found = detector.detect(frame)
    return found


def test_a_moving_speck_is_not_a_candidate() -> None:
    found = _last_detections(speck=3)  # a few dozen moving pixels at most, under 0.05 % of 320 x 240
    assert len(found) == 1 and 60 < found[0].box[0] < 80


def test_each_blob_scores_its_share_of_the_moving_area() -> None:
    big, small = _last_detections()
    assert big.score + small.score == pytest.approx(1.0)
    assert big.score / small.score == pytest.approx(big.box[2] * big.box[3] / (small.box[2] * small.box[3]), rel=0.3)
