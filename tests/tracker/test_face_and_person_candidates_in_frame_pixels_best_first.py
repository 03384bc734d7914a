"""The OpenCV face and person detectors' answers as candidates: boxes in the frame's own pixels
(the person detector works on frames shrunk to 640 px) and the best candidate first. OpenCV's own
detectors are replaced by stand-ins with known answers (the synthetic frames hold no faces or people)."""
from __future__ import annotations

import numpy as np
import pytest

from tracker.detectors import HaarFaceDetector, HogPersonDetector


class _Hog:
    """Stands in for ``cv2.HOGDescriptor``: two people, in the pixels of the image it is given."""

    winSize = (64, 128)

    def __init__(self) -> None:
        self.shapes: list[tuple[int, ...]] = []

    def detectMultiScale(self, image: np.ndarray, **options: object) -> tuple[np.ndarray, np.ndarray]:
        self.shapes.append(image.shape)
        return np.array([[10, 20, 64, 128], [300, 40, 80, 160]]), np.array([[-0.5], [1.5]])


class _Cascade:
    """Stands in for ``cv2.CascadeClassifier``: two faces, the second merged from more raw hits."""

    def detectMultiScale2(self, image: np.ndarray, **options: object) -> tuple[np.ndarray, np.ndarray]:
        return np.array([[10, 10, 30, 30], [100, 50, 40, 40]]), np.array([3, 12])


def test_person_boxes_are_in_the_frames_pixels_and_best_first(monkeypatch: pytest.MonkeyPatch) -> None:
    detector = HogPersonDetector()
    hog = _Hog()
    monkeypatch.setattr(detector, "_hog", hog)
    found = detector.detect(np.zeros((720, 1280, 3), np.uint8))
    assert hog.shapes == [(360, 640, 3)]  # shrunk by 2
    assert [d.box for d in found] == [(600.0, 80.0, 160.0, 320.0), (20.0, 40.0, 128.0, 256.0)]
    assert found[0].score > found[1].score


def test_faces_are_best_first(monkeypatch: pytest.MonkeyPatch) -> None:
    detector = HaarFaceDetector()
    monkeypatch.setattr(detector, "_cascade", _Cascade())
    found = detector.detect(np.zeros((240, 320, 3), np.uint8))
    assert [d.box for d in found] == [(100.0, 50.0, 40.0, 40.0), (10.0, 10.0, 30.0, 30.0)]
    assert 0.0 < found[1].score < found[0].score < 1.0
