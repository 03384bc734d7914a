"""Detectors that find a subject to start on: faces, people and the largest moving thing.

Every detector takes grey (H x W or H x W x 1), BGR and BGRA ``uint8`` frames; an empty frame gives nothing.
"""
from __future__ import annotations

import functools
from collections import deque
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Protocol

import cv2
import numpy as np

from tracker.backends.model_files import checked_model_dir, find_model_file
from tracker.detectors import camera_motion
from tracker.runtime.boxes import Box
from tracker.runtime.frames import as_bgr, as_bgr_or_grey, as_grey, check_frame

DETECTOR_KINDS = ("face", "person", "motion")
HAAR_FACE = "haarcascade_frontalface_default.xml"
MOTION_WORK_SIDE = 640  # the motion detector shrinks larger frames to this many px on their longer side
ADOPT_FRAMES = 3  # foreground in which nothing moved for this many frames becomes background
_NEIGHBOURS = np.ones((3, 3), np.uint8)


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
        if check_frame(frame).size == 0:
            return []
        grey = cv2.equalizeHist(as_grey(frame))
        boxes, hits = self._cascade.detectMultiScale2(grey, scaleFactor=1.1, minNeighbors=4, minSize=(20, 20))
        found = [Detection(tuple(float(v) for v in b), float(1.0 - np.exp(-n / 8.0))) for b, n in zip(boxes, hits)]
        return sorted(found, key=lambda d: d.score, reverse=True)


class YuNetFaceDetector:
    """YuNet (``cv2.FaceDetectorYN``); needs ``face_detection_yunet*.onnx`` in the model dir."""

    def __init__(self, model_dir: str | Path | None, score_threshold: float = 0.6) -> None:
        model = find_model_file(model_dir, "yunet", "face_detection_yunet*.onnx", "YuNet face detector")
        try:  # a damaged file fails to load, another network at its first frame: both named here
            self._net = cv2.FaceDetectorYN.create(str(model), "", (320, 320), score_threshold)
            self._net.detect(np.zeros((320, 320, 3), np.uint8))
        except cv2.error:
            raise ValueError(f"YuNet face detector {model}: not a YuNet network (damaged or another file?)") from None

    def detect(self, frame: np.ndarray) -> list[Detection]:
        if check_frame(frame).size == 0:
            return []
        height, width = frame.shape[:2]
        self._net.setInputSize((width, height))
        _, faces = self._net.detect(as_bgr(frame))
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
        if not self._fits_window(check_frame(frame)):
            return []
        scale = min(1.0, self._max_side / max(frame.shape[:2]))
        image = cv2.resize(frame, None, fx=scale, fy=scale, interpolation=cv2.INTER_AREA) if scale < 1 else frame
        if not self._fits_window(image):
            return []
        boxes, weights = self._hog.detectMultiScale(as_bgr_or_grey(image), winStride=(8, 8), padding=(8, 8),
                                                    scale=1.05)
        found = [Detection(tuple(float(v) / scale for v in b), float(1.0 / (1.0 + np.exp(-float(w)))))
                 for b, w in zip(boxes, np.ravel(weights))]
        return sorted(found, key=lambda d: d.score, reverse=True)

    def _fits_window(self, image: np.ndarray) -> bool:
        """Whether ``image`` holds at least one detection window."""
        window_w, window_h = self._hog.winSize
        return image.shape[1] >= window_w and image.shape[0] >= window_h


class MotionDetector:
    """Moving blobs, largest first, from a still or moving camera.

    A moving thing is where the newest frame differs from the background, in patches where
    something moves now (the newest frame differs from both of the two before it), plus the
    moving pixels the background does not explain: its box covers it where it is, flat-coloured
    or textured, not the ground it left. A pixel's background is a level it kept (within
    ``threshold``) for ``settle_frames`` frames, or over the first three frames away from what
    moved in them. Where none is known yet (behind a thing moving from the start) moving pixels
    alone mark it, so a textured thing trails its last step and a flat one shows only its edges
    until the ground behind it has been seen. Foreground in which nothing moved for
    ``ADOPT_FRAMES`` frames (the ground a thing left, edges after the camera shook) becomes
    background. When the camera moved between two frames (panned, turned on a gimbal, shaken in the
    hand; :func:`tracker.detectors.camera_motion.camera_motion`), the earlier frames and the background are
    first carried into the new frame's pixels, and the strip at the edge that they did not see
    says nothing. A change over more than ``restart_fraction`` of the picture (the light, a camera
    motion that could not be told) or of the frame size starts afresh. The score is the blob's
    share of the moving area. Needs three frames before it reports anything. Works on frames shrunk
    to ``MOTION_WORK_SIDE`` px; boxes are in the frame's pixels.
    """

    def __init__(self, threshold: int = 20, min_area_fraction: float = 0.0005, settle_frames: int = 30,
                 restart_fraction: float = 0.5) -> None:
        if not 1 <= settle_frames <= 255:
            raise ValueError(f"settle_frames must be 1..255, not {settle_frames}")
        self._threshold = threshold
        self._min_area_fraction = min_area_fraction
        self._settle_frames = settle_frames
        self._restart_fraction = restart_fraction
        self._history: deque[np.ndarray] = deque(maxlen=3)
        self._seen: deque[np.ndarray | None] = deque(maxlen=3)  # per frame: the pixels of the newest it saw (None: all)
        self._background: _Background | None = None

    def detect(self, frame: np.ndarray) -> list[Detection]:
        if check_frame(frame).size == 0:
            return []
        grey = _work_grey(frame)
        if self._history and self._history[-1].shape != grey.shape:
            self._restart()
        if self._history:
            matrix = camera_motion.camera_motion(self._history[-1], grey)
            if matrix is not None:
                self._follow_camera(matrix)
        self._history.append(grey)
        self._seen.append(None)
        if len(self._history) < 3:
            return []
        mask = self._moving_things(grey, self._moving_now(*self._history))
        if cv2.countNonZero(mask) > self._restart_fraction * mask.size:
            self._restart()
        mask = cv2.morphologyEx(mask, cv2.MORPH_CLOSE, _kernel(mask.shape), iterations=2)
        _, _, stats, _ = _components(mask)
        return self._blobs(stats, mask.size, (frame.shape[1] / grey.shape[1], frame.shape[0] / grey.shape[0]))

    def _restart(self) -> None:
        self._history.clear()
        self._seen.clear()
        self._background = None

    def _follow_camera(self, matrix: np.ndarray) -> None:
        """Carry the two latest frames (the next one pushes the third out), what they saw and the
        background by the camera's ``matrix`` into the next frame's pixels."""
        covered = camera_motion.covered(self._history[-1].shape, matrix)
        self._history = deque((camera_motion.warp(h, matrix) for h in list(self._history)[-2:]), maxlen=3)
        self._seen = deque((covered if s is None else cv2.bitwise_and(covered, camera_motion.warp(s, matrix, True))
                            for s in list(self._seen)[-2:]), maxlen=3)
        if self._background is not None:
            self._background.follow(matrix, covered)

    def _seen_by_all(self) -> np.ndarray | None:
        """The pixels of the newest frame that every remembered frame saw (0 or 255; None: all)."""
        masks = [s for s in self._seen if s is not None]
        return functools.reduce(cv2.bitwise_and, masks) if masks else None

    def _moving_now(self, older: np.ndarray, previous: np.ndarray, current: np.ndarray) -> np.ndarray:
        """Pixels where the newest frame differs from both of the two before it, where both saw it (0 or 255)."""
        moving = cv2.bitwise_and(_differs(current, previous, self._threshold),
                                 _differs(current, older, self._threshold))
        seen = self._seen_by_all()
        return moving if seen is None else cv2.bitwise_and(moving, seen)

    def _moving_things(self, grey: np.ndarray, moving: np.ndarray) -> np.ndarray:
        """Foreground patches holding a ``moving`` pixel, and the moving pixels the background does not
        explain (0 or 255); learns the background from ``grey`` on the way."""
        if self._background is None:
            self._background = _Background(self._history, self._threshold, self._settle_frames, self._seen_by_all())
        else:
            self._background.learn(grey)
        foreground = self._background.foreground(grey)
        count, labels = cv2.connectedComponents(foreground)
        holds = np.zeros(count, bool)
        holds[labels[moving > 0]] = True
        holds[0] = True  # the label of everything else
        if not holds.all():
            still = ~holds[labels]
            self._background.adopt(grey, still)
            foreground[still] = 0
        return cv2.bitwise_or(foreground, cv2.bitwise_and(moving, self._background.unexplained(grey)))

    def _blobs(self, stats: np.ndarray, image_area: int, scale: tuple[float, float]) -> list[Detection]:
        """The blobs (``stats`` of connected components) large enough, boxed in frame pixels."""
        total = float(stats[1:, cv2.CC_STAT_AREA].sum()) or 1.0
        sx, sy = scale
        found = [Detection((float(x * sx), float(y * sy), float(w * sx), float(h * sy)), float(area / total))
                 for x, y, w, h, area in stats[1:] if area >= self._min_area_fraction * image_area]
        return sorted(found, key=lambda d: d.box[2] * d.box[3], reverse=True)


class _Background:
    """Each pixel's background grey level, where known (see :class:`MotionDetector`).

    A pixel holds its level while it stays within ``threshold`` of the level it took last (a slow
    drift cannot carry it away); a pixel next to a change does not hold, so flat patches of a
    moving thing are not learnt.
    """

    def __init__(self, frames: Sequence[np.ndarray], threshold: int, settle_frames: int,
                 seen: np.ndarray | None = None) -> None:
        """Start from the first three ``frames`` (in the last one's pixels): outside the boxes of
        whatever changed in them, known; only where all three ``seen`` it (0 or 255, None: all)."""
        self._threshold = threshold
        self._settle_frames = settle_frames
        first, second, current = frames
        changed = cv2.bitwise_or(_differs(second, first, threshold), _differs(current, first, threshold))
        if seen is None:
            self._known = cv2.bitwise_not(_boxes_around(changed))
        else:
            self._known = cv2.bitwise_and(cv2.bitwise_not(_boxes_around(cv2.bitwise_and(changed, seen))), seen)
        self._level = current.copy()
        self._held = current.copy()  # the level each pixel holds to
        self._age = np.zeros_like(current)  # frames it has held it, up to 255

    def learn(self, grey: np.ndarray) -> None:
        """Take in the newest frame: a level held for ``settle_frames`` becomes the background."""
        changed = cv2.dilate(_differs(grey, self._held, self._threshold), _kernel(grey.shape))
        cv2.copyTo(grey, changed, self._held)
        self._age = cv2.bitwise_and(cv2.add(self._age, 1), cv2.bitwise_not(changed))
        settled = cv2.compare(self._age, self._settle_frames, cv2.CMP_GE)
        cv2.copyTo(grey, settled, self._level)
        cv2.bitwise_or(self._known, settled, self._known)

    def follow(self, matrix: np.ndarray, seen: np.ndarray) -> None:
        """Carry the background by the camera's ``matrix`` into the next frame's pixels; it is known,
        and a level held, only where the last frame ``seen`` it (0 or 255)."""
        self._level = camera_motion.warp(self._level, matrix)
        self._held = camera_motion.warp(self._held, matrix)
        self._age = cv2.bitwise_and(camera_motion.warp(self._age, matrix, nearest=True), seen)
        self._known = cv2.bitwise_and(camera_motion.warp(self._known, matrix, nearest=True), seen)

    def adopt(self, grey: np.ndarray, still: np.ndarray) -> None:
        """Take ``grey`` as the background where ``still`` (bool) once it has held there for ``ADOPT_FRAMES``."""
        where = still & (self._age >= ADOPT_FRAMES)
        np.copyto(self._level, grey, where=where)
        self._known[where] = 255

    def foreground(self, grey: np.ndarray) -> np.ndarray:
        """Pixels of known background that ``grey`` differs from (0 or 255): brighter than the brightest
        or darker than the darkest background level within a pixel, in patches over two pixels wide
        (a camera that shook by a pixel or two leaves no edges)."""
        brighter = cv2.subtract(grey, cv2.dilate(self._level, _NEIGHBOURS))
        darker = cv2.subtract(cv2.erode(self._level, _NEIGHBOURS), grey)
        differs = cv2.threshold(cv2.max(brighter, darker), self._threshold, 255, cv2.THRESH_BINARY)[1]
        return cv2.morphologyEx(cv2.bitwise_and(differs, self._known), cv2.MORPH_OPEN, _NEIGHBOURS)

    def unexplained(self, grey: np.ndarray) -> np.ndarray:
        """Pixels whose background is unknown or differs from ``grey`` (0 or 255)."""
        return cv2.bitwise_or(cv2.bitwise_not(self._known), _differs(grey, self._level, self._threshold))


def _boxes_around(changed: np.ndarray) -> np.ndarray:
    """The bounding boxes of the closed blobs of ``changed``, filled (0 or 255): where something moved,
    flat patches of it included."""
    closed = cv2.morphologyEx(changed, cv2.MORPH_CLOSE, _kernel(changed.shape), iterations=2)
    _, _, stats, _ = _components(closed)
    boxes = cv2.dilate(changed, _kernel(changed.shape))
    for x, y, w, h, _ in stats[1:]:
        boxes[y:y + h, x:x + w] = 255
    return boxes


def _components(mask: np.ndarray) -> tuple[int, np.ndarray, np.ndarray, np.ndarray]:
    """``cv2.connectedComponentsWithStats`` by the BBDT algorithm: 2-3 times as fast as the default's."""
    return cv2.connectedComponentsWithStatsWithAlgorithm(mask, 8, cv2.CV_32S, cv2.CCL_BBDT)


def _work_grey(frame: np.ndarray) -> np.ndarray:
    """``frame`` in grey, averaged down to ``MOTION_WORK_SIDE`` px when larger, and blurred against noise."""
    grey = as_grey(frame)
    shrink = -(-max(grey.shape) // MOTION_WORK_SIDE)
    if shrink > 1:
        size = (max(1, grey.shape[1] // shrink), max(1, grey.shape[0] // shrink))
        grey = cv2.resize(grey, size, interpolation=cv2.INTER_AREA)
    return cv2.GaussianBlur(grey, (5, 5), 0)


def _differs(a: np.ndarray, b: np.ndarray, threshold: int) -> np.ndarray:
    """Pixels where two grey images differ by more than ``threshold`` (0 or 255)."""
    return cv2.threshold(cv2.absdiff(a, b), threshold, 255, cv2.THRESH_BINARY)[1]


@functools.lru_cache(maxsize=8)
def _kernel(shape: tuple[int, ...]) -> np.ndarray:
    """The ellipse, about 1/80 of the longer side of ``shape``, that closes gaps between moving pixels
    and marks a change's neighbourhood."""
    k = max(3, int(round(max(shape) / 80)) | 1)
    return cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (k, k))


def make_detector(kind: str, model_dir: str | Path | None = None) -> Detector:
    """A detector by kind: ``face`` (YuNet when ``model_dir`` holds its file, else Haar), ``person`` or
    ``motion``; a ``model_dir`` that is no folder is a ``FileNotFoundError``."""
    model_dir = checked_model_dir(model_dir)
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
