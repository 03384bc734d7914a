"""Detectors that find a subject to start on: faces, people and the largest moving thing."""
from __future__ import annotations

import functools
from collections import deque
from dataclasses import dataclass
from pathlib import Path
from typing import Protocol

import cv2
import numpy as np

from tracker.boxes import Box
from tracker.features import to_grey
from tracker.model_files import find_model_file

DETECTOR_KINDS = ("face", "person", "motion")
HAAR_FACE = "haarcascade_frontalface_default.xml"


@dataclass(frozen=True)
class Detection:
    """A candidate subject: its box (x, y, w, h) and a score in 0..1."""

    box: Box
    score: float


class Detector(Protocol):
    def detect(self, frame: np.ndarray) -> list[Detection]:
        """Candidates in ``frame``, best first."""


class HaarFaceDetector:
    """OpenCV's frontal-face Haar cascade (ships with the wheel; no download needed).

    The score grows with the number of overlapping raw hits that were merged into the face.
    """

    def __init__(self, cascade_path: str | Path | None = None) -> None:
        path = Path(cascade_path) if cascade_path else Path(cv2.data.haarcascades) / HAAR_FACE
        if not path.is_file():
            raise FileNotFoundError(f"Haar face cascade not found: {path}")
        self._cascade = cv2.CascadeClassifier(str(path))
        if self._cascade.empty():
            raise ValueError(f"cannot load Haar cascade {path}")

    def detect(self, frame: np.ndarray) -> list[Detection]:
        grey = cv2.equalizeHist(to_grey(frame))
        boxes, hits = self._cascade.detectMultiScale2(grey, scaleFactor=1.1, minNeighbors=4, minSize=(20, 20))
        found = [Detection(tuple(float(v) for v in b), float(1.0 - np.exp(-n / 8.0))) for b, n in zip(boxes, hits)]
        return sorted(found, key=lambda d: d.score, reverse=True)


class YuNetFaceDetector:
    """YuNet (``cv2.FaceDetectorYN``); needs ``face_detection_yunet*.onnx`` in the model dir."""

    def __init__(self, model_dir: str | Path | None, score_threshold: float = 0.6) -> None:
        model = find_model_file(model_dir, "yunet", "face_detection_yunet*.onnx", "YuNet face detector")
        self._net = cv2.FaceDetectorYN.create(str(model), "", (320, 320), score_threshold)

    def detect(self, frame: np.ndarray) -> list[Detection]:
        height, width = frame.shape[:2]
        self._net.setInputSize((width, height))
        _, faces = self._net.detect(frame)
        if faces is None:
            return []
        found = [Detection(tuple(float(v) for v in f[:4]), float(f[-1])) for f in faces]
        return sorted(found, key=lambda d: d.score, reverse=True)


class HogPersonDetector:
    """OpenCV's HOG + linear SVM people detector (built in; finds people ~100 px tall and up).

    Frames smaller than its 64 x 128 px window (after shrinking to ``max_side``) give no detections:
    OpenCV's detector corrupts memory on them.
    """

    def __init__(self, max_side: int = 640) -> None:
        self._hog = cv2.HOGDescriptor()
        self._hog.setSVMDetector(cv2.HOGDescriptor_getDefaultPeopleDetector())
        self._max_side = max_side

    def detect(self, frame: np.ndarray) -> list[Detection]:
        if not self._fits_window(frame):
            return []
        scale = min(1.0, self._max_side / max(frame.shape[:2]))
        image = cv2.resize(frame, None, fx=scale, fy=scale, interpolation=cv2.INTER_AREA) if scale < 1 else frame
        if not self._fits_window(image):
            return []
        boxes, weights = self._hog.detectMultiScale(image, winStride=(8, 8), padding=(8, 8), scale=1.05)
        found = [Detection(tuple(float(v) / scale for v in b), float(1.0 / (1.0 + np.exp(-float(w)))))
                 for b, w in zip(boxes, np.ravel(weights))]
        return sorted(found, key=lambda d: d.score, reverse=True)

    def _fits_window(self, image: np.ndarray) -> bool:
        """Whether ``image`` holds at least one detection window."""
        window_w, window_h = self._hog.winSize
        return image.shape[1] >= window_w and image.shape[0] >= window_h


class MotionDetector:
    """Moving blobs from a static camera, largest first (three-frame differencing).

    A pixel is moving when the newest frame differs from both of the two before it, which
    marks where a moving object is now rather than where it was. The score is the blob's
    share of the moving area in the frame. Needs three frames before it reports anything.
    """

    def __init__(self, threshold: int = 20, min_area_fraction: float = 0.0005) -> None:
        self._threshold = threshold
        self._min_area_fraction = min_area_fraction
        self._history: deque[np.ndarray] = deque(maxlen=3)

    def detect(self, frame: np.ndarray) -> list[Detection]:
        grey = cv2.GaussianBlur(to_grey(frame), (5, 5), 0)
        self._history.append(grey)
        if len(self._history) < 3:
            return []
        return self._blobs(self._moving_mask(*self._history))

    def _moving_mask(self, older: np.ndarray, previous: np.ndarray, current: np.ndarray) -> np.ndarray:
        mask = (cv2.absdiff(current, previous) > self._threshold) & (cv2.absdiff(current, older) > self._threshold)
        mask = mask.astype(np.uint8) * 255
        return cv2.morphologyEx(mask, cv2.MORPH_CLOSE, _closing_kernel(mask.shape), iterations=2)

    def _blobs(self, mask: np.ndarray) -> list[Detection]:
        count, _, stats, _ = cv2.connectedComponentsWithStats(mask)
        frame_area = float(mask.size)
        total = float(stats[1:, cv2.CC_STAT_AREA].sum()) or 1.0
        found = [Detection(tuple(float(v) for v in stats[i, :4]), float(stats[i, cv2.CC_STAT_AREA] / total))
                 for i in range(1, count) if stats[i, cv2.CC_STAT_AREA] >= self._min_area_fraction * frame_area]
        return sorted(found, key=lambda d: d.box[2] * d.box[3], reverse=True)


@functools.lru_cache(maxsize=8)
def _closing_kernel(shape: tuple[int, ...]) -> np.ndarray:
    """The ellipse that closes gaps in a moving-pixel mask of ``shape`` (about 1/80 of its longer side)."""
    k = max(3, int(round(max(shape) / 80)) | 1)
    return cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (k, k))


def make_detector(kind: str, model_dir: str | Path | None = None) -> Detector:
    """A detector by kind: ``face`` (YuNet when ``model_dir`` holds its file, else Haar), ``person`` or ``motion``."""
    if kind == "face":
        return _face_detector(model_dir)
    if kind == "person":
        return HogPersonDetector()
    if kind == "motion":
        return MotionDetector()
    raise ValueError(f"unknown detector kind {kind!r} (known: {', '.join(DETECTOR_KINDS)})")


def _face_detector(model_dir: str | Path | None) -> Detector:
    """YuNet when ``model_dir`` holds ``face_detection_yunet*.onnx``, else the Haar cascade (a model
    folder with NanoTrack's files only still gives face detection)."""
    try:
        return YuNetFaceDetector(model_dir)
    except FileNotFoundError:
        return HaarFaceDetector()
