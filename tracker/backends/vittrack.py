"""VitTrack on onnxruntime: one transformer network taking a template and a search crop.

Pre- and post-processing follow OpenCV's ``TrackerVit`` (square crops of 2 and 4 times the box's
geometric-mean side, a 16 x 16 confidence map weighted by a Hann window, box size and centre offset
per cell, all relative to the search crop), except the normalisation: the network wants each
channel of the BGR crop in [0, 1], minus its mean and divided by its std. OpenCV computes ``1/std``
with ``cv::Scalar`` division, which is quaternion division, so green and red come out with the
wrong sign and scale (docs/tracker.md); here it is plain per-channel arithmetic.

The confidence map is meaningful: its windowed peak is the backend's score, low on background and
under occlusion. ``likeness`` scores a candidate box by the peak near the middle of a search crop
centred on it, over the subject's typical peak.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np

from tracker.backends.model_files import find_model_file
from tracker.backends.nanotrack import crop_square
from tracker.backends.onnx_sessions import DEFAULT_THREADS, OnnxNetwork
from tracker.runtime.boxes import Box, from_center
from tracker.runtime.typical import RunningTypical

TEMPLATE_SIZE = 128  # template crop side, pixels
SEARCH_SIZE = 256  # search crop side, pixels
MAP_SIZE = 16  # confidence / size / offset map side
TEMPLATE_FACTOR = 2.0  # template crop side over the box's geometric-mean side
SEARCH_FACTOR = 4.0  # search crop side over the box's geometric-mean side
MEAN = np.array([0.485, 0.456, 0.406], np.float32)  # per channel, in the order fed (B, G, R)
STD = np.array([0.229, 0.224, 0.225], np.float32)
#: Each channel's normalised value for every 8-bit level (3, 256): a lookup per pixel costs a quarter
#: of the arithmetic on a whole float crop, for the same float32 values.
_LEVELS = ((np.arange(256, dtype=np.float32)[None] / np.float32(255.0) - MEAN[:, None]) / STD[:, None]).astype(np.float32)
MIN_SIZE = 4.0  # smallest box side kept, pixels


@dataclass(frozen=True)
class VitTrackParams:
    """The reference settings: the box is held where the windowed confidence is under ``hold_below``."""

    hold_below: float = 0.2  # OpenCV's tracking_score_threshold


def vittrack_model_file(model_dir: str | Path | None) -> Path:
    """``vitTracker*.onnx`` in ``model_dir`` or its ``vittrack/``."""
    return find_model_file(model_dir, "vittrack", "vitTracker*.onnx", "VitTrack")


def centred_hann(size: int) -> np.ndarray:
    """OpenCV's centred Hann window (size x size): positive up to the border, as TrackerVit uses."""
    hann = 0.5 * (1 - np.cos(2 * np.pi * (np.arange(size) + 1) / (size + 1)))
    return np.outer(hann, hann).astype(np.float32)


def normalised_blob(crop: np.ndarray) -> np.ndarray:
    """The (1, 3, H, W) network input of a BGR (or grey) ``uint8`` crop: per channel, [0, 1] minus
    ``MEAN`` over ``STD``."""
    if crop.ndim == 2:
        crop = cv2.cvtColor(crop, cv2.COLOR_GRAY2BGR)
    blob = np.empty((1, 3, *crop.shape[:2]), np.float32)
    for channel in range(3):
        np.take(_LEVELS[channel], crop[:, :, channel], out=blob[0, channel])
    return blob


def decode_peak(conf: np.ndarray, size: np.ndarray, offset: np.ndarray,
                window: np.ndarray) -> tuple[tuple[float, float, float, float], float]:
    """The box (cx, cy, w, h) as fractions of the search crop at the windowed confidence's peak, and
    that windowed confidence. ``conf`` is (16, 16), ``size`` and ``offset`` (2, 16, 16)."""
    weighted = conf * window
    row, col = np.unravel_index(int(np.argmax(weighted)), weighted.shape)
    cx = (col + offset[0, row, col]) / MAP_SIZE
    cy = (row + offset[1, row, col]) / MAP_SIZE
    return (float(cx), float(cy), float(size[0, row, col]), float(size[1, row, col])), float(weighted[row, col])


class VitTrackBackend:
    """VitTrack (``TrackingBackend``): score = the windowed confidence map's peak."""

    def __init__(self, model_dir: str | Path | None, params: VitTrackParams | None = None,
                 threads: int = DEFAULT_THREADS) -> None:
        self.name = "vittrack"
        self.params = params or VitTrackParams()
        self._net = OnnxNetwork(
            vittrack_model_file(model_dir), "VitTrack network",
            {"template": (1, 3, TEMPLATE_SIZE, TEMPLATE_SIZE), "search": (1, 3, SEARCH_SIZE, SEARCH_SIZE)},
            {"output1": (1, 1, MAP_SIZE, MAP_SIZE), "output2": (1, 2, MAP_SIZE, MAP_SIZE),
             "output3": (1, 2, MAP_SIZE, MAP_SIZE)}, threads)
        self._window = centred_hann(MAP_SIZE)
        self._template: np.ndarray | None = None
        self._center = np.zeros(2)
        self._size = np.ones(2)
        self._typical = RunningTypical()

    def init(self, frame: np.ndarray, box: Box) -> None:
        self.relocate(box)
        side = TEMPLATE_FACTOR * float(np.sqrt(np.prod(self._size)))
        self._template = normalised_blob(crop_square(frame, *self._center, side, TEMPLATE_SIZE, (0.0, 0.0, 0.0)))
        self._typical.reset()

    def update(self, frame: np.ndarray) -> tuple[Box | None, float]:
        if self._template is None:
            raise RuntimeError(f"{self.name}: update() before init()")
        (cx, cy, w, h), score = self._search(frame, self._center, self._size)
        self._typical.relative(score)
        if score < self.params.hold_below:
            return None, score
        frame_size = np.array(frame.shape[1::-1], dtype=float)
        self._center = np.clip([cx, cy], 0, frame_size)
        self._size = np.clip([w, h], MIN_SIZE, frame_size)
        return from_center(*(float(v) for v in self._center), *(float(v) for v in self._size)), score

    def relocate(self, box: Box) -> None:
        """Search around ``box`` (taken as the subject's) from the next frame on, keeping the template."""
        x, y, w, h = (float(v) for v in box)
        self._center = np.array([x + w / 2, y + h / 2])
        self._size = np.array([max(w, 1.0), max(h, 1.0)])

    def likeness(self, frame: np.ndarray, box: Box) -> float:
        """The windowed confidence of a search centred on ``box`` (at its size) over the subject's
        typical confidence (1 while that is unknown); one network pass."""
        x, y, w, h = (float(v) for v in box)
        _, score = self._search(frame, np.array([x + w / 2, y + h / 2]), np.array([max(w, 1.0), max(h, 1.0)]))
        return self._typical.ratio(score)

    def _search(self, frame: np.ndarray, center: np.ndarray,
                size: np.ndarray) -> tuple[tuple[float, float, float, float], float]:
        """The box (cx, cy, w, h) in image pixels found in the search crop around ``center`` for a
        subject of ``size``, and its windowed confidence."""
        side = SEARCH_FACTOR * float(np.sqrt(np.prod(size)))
        crop = crop_square(frame, *center, side, SEARCH_SIZE, (0.0, 0.0, 0.0))
        out = self._net.run(template=self._template, search=normalised_blob(crop))
        (fx, fy, fw, fh), score = decode_peak(out["output1"][0, 0], out["output2"][0], out["output3"][0], self._window)
        left, top = center[0] - side / 2, center[1] - side / 2
        return (left + fx * side, top + fy * side, fw * side, fh * side), score
