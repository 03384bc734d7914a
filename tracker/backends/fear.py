"""FEAR-XS on onnxruntime: a template network run once per start, a search network per frame.

Pre- and post-processing follow PinataFarms' FEARTracker: crops are the box grown by a fraction of
its width and height on each side (20 % for the template, 200 % for the search), so not square,
padded with the frame's mean colour and resized to 128 / 256 px, fed as RGB 0-255; the search
network gives classification logits and box sides (left, top, right, bottom) in search-crop pixels
from a 16 x 16 grid of points 16 px apart around the crop's centre, and the best cell's box is
taken as it is (the reference uses no window or size penalty by default).

The backend's score is the chosen cell's sigmoid probability. ``likeness`` compares the template
network's features of a candidate box with the subject's (cosine), over their typical value.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np

from tracker.backends.model_files import find_model_file
from tracker.backends.nanotrack import cosine_likeness, hanning_window
from tracker.backends.onnx_sessions import DEFAULT_THREADS, OnnxNetwork
from tracker.runtime.boxes import Box
from tracker.runtime.crops import resample_window
from tracker.runtime.typical import RunningTypical

TEMPLATE_SIZE = 128  # template crop side, pixels
SEARCH_SIZE = 256  # search crop side, pixels
MAP_SIZE = 16  # score / box map side
STRIDE = 16  # search-crop pixels between map points
FEATURES = (1, 256, 8, 8)  # the template network's output
TEMPLATE_GROWTH = 0.2  # the template crop adds this much of the box's width / height on each side
SEARCH_GROWTH = 2.0  # the search crop adds this much on each side
MIN_SIZE = 3.0  # smallest box side kept, pixels (the reference's)
# The subject's typical template-feature likeness is measured on its confident frames (probability
# at least LIKENESS_SCORE), one in LIKENESS_EVERY: a template pass is a sizeable share of a search.
LIKENESS_SCORE = 0.5
LIKENESS_EVERY = 10


@dataclass(frozen=True)
class FearParams:
    """Post-processing: ``window_influence`` 0 takes the best cell as the reference does."""

    window_influence: float = 0.0


def fear_model_files(model_dir: str | Path | None) -> tuple[Path, Path]:
    """The template and search networks' files in ``model_dir`` or its ``fear_xs/``."""
    template = find_model_file(model_dir, "fear_xs", "fear_xs_template*.onnx", "FEAR-XS")
    search = find_model_file(model_dir, "fear_xs", "fear_xs_search*.onnx", "FEAR-XS")
    return template, search


def grid_points(size: int = MAP_SIZE, stride: int = STRIDE, crop: int = SEARCH_SIZE) -> np.ndarray:
    """The map points' positions along one axis of the search crop, pixels (the reference's grid:
    ``(i - size // 2) * stride + crop // 2``)."""
    return ((np.arange(size) - size // 2) * stride + crop // 2).astype(np.float32)


def sigmoid(x: np.ndarray) -> np.ndarray:
    return 1.0 / (1.0 + np.exp(-x))


def rgb_blob(crop: np.ndarray) -> np.ndarray:
    """The (1, 3, H, W) float RGB 0-255 input of a BGR or grey ``uint8`` crop."""
    rgb = cv2.cvtColor(crop, cv2.COLOR_GRAY2RGB if crop.ndim == 2 else cv2.COLOR_BGR2RGB)
    return rgb.astype(np.float32).transpose(2, 0, 1)[None]


def decode_best(cls: np.ndarray, bbox: np.ndarray, window: np.ndarray | None,
                influence: float) -> tuple[tuple[float, float, float, float], float]:
    """The box (x1, y1, x2, y2) in search-crop pixels at the best cell and that cell's probability.
    ``cls`` is (16, 16) logits, ``bbox`` (4, 16, 16) distances to left, top, right and bottom."""
    score = sigmoid(cls)
    ranked = score if window is None or influence <= 0 else score * (1 - influence) + window * influence
    row, col = np.unravel_index(int(np.argmax(ranked)), ranked.shape)
    points = grid_points()
    gx, gy = points[col], points[row]
    left, top, right, bottom = bbox[:, row, col]
    return (float(gx - left), float(gy - top), float(gx + right), float(gy + bottom)), float(score[row, col])


class FearBackend:
    """FEAR-XS (``TrackingBackend``): score = the chosen cell's classification probability."""

    def __init__(self, model_dir: str | Path | None, params: FearParams | None = None,
                 threads: int = DEFAULT_THREADS) -> None:
        self.name = "fear"
        self.params = params or FearParams()
        template, search = fear_model_files(model_dir)
        self._template_net = OnnxNetwork(template, "FEAR-XS template network",
                                         {"image": (1, 3, TEMPLATE_SIZE, TEMPLATE_SIZE)}, {"features": FEATURES},
                                         threads)
        self._search_net = OnnxNetwork(search, "FEAR-XS search network",
                                       {"image": (1, 3, SEARCH_SIZE, SEARCH_SIZE), "template_features": FEATURES},
                                       {"bbox": (1, 4, MAP_SIZE, MAP_SIZE), "cls": (1, 1, MAP_SIZE, MAP_SIZE)},
                                       threads)
        self._window = hanning_window(MAP_SIZE)
        self._features: np.ndarray | None = None
        self._box = np.zeros(4)  # x, y, w, h
        self._fill = (0.0, 0.0, 0.0)
        self._typical = RunningTypical()
        self._updates = 0

    def init(self, frame: np.ndarray, box: Box) -> None:
        self._box = np.array([float(v) for v in box])
        self._box[2:] = np.maximum(self._box[2:], 1.0)
        self._fill = tuple(float(v) for v in cv2.mean(frame)[:3])
        self._features = self._template_features(frame, self._box)
        self._typical.reset()
        self._updates = 0

    def update(self, frame: np.ndarray) -> tuple[Box | None, float]:
        if self._features is None:
            raise RuntimeError(f"{self.name}: update() before init()")
        x, y, w, h = self._box
        grown = np.array([w, h]) * (1 + 2 * SEARCH_GROWTH)
        center = np.array([x + w / 2, y + h / 2])
        crop = _crop(frame, center, grown, SEARCH_SIZE, self._fill)
        out = self._search_net.run(image=rgb_blob(crop), template_features=self._features)
        (x1, y1, x2, y2), score = decode_best(out["cls"][0, 0], out["bbox"][0], self._window,
                                              self.params.window_influence)
        scale = grown / SEARCH_SIZE  # image pixels per crop pixel (x, y)
        origin = center - grown / 2
        left, top = origin + np.array([x1, y1]) * scale
        right, bottom = origin + np.array([x2, y2]) * scale
        frame_w, frame_h = frame.shape[1], frame.shape[0]
        left, right = np.clip([left, right], 0, frame_w)
        top, bottom = np.clip([top, bottom], 0, frame_h)
        width = max(MIN_SIZE, right - left)
        height = max(MIN_SIZE, bottom - top)
        self._box = np.array([min(left, frame_w - width), min(top, frame_h - height), width, height])
        self._updates += 1
        if score >= LIKENESS_SCORE and self._updates % LIKENESS_EVERY == 1:
            self._typical.relative(cosine_likeness(self._features, self._template_features(frame, self._box)))
        return tuple(float(v) for v in self._box), score

    def likeness(self, frame: np.ndarray, box: Box) -> float:
        """The template network's features of ``box`` against the subject's (cosine), over the
        typical likeness of the subject's own boxes (1 while that is unknown); one template pass."""
        if self._features is None:
            return 1.0
        found = self._template_features(frame, np.array([float(v) for v in box]))
        return self._typical.ratio(cosine_likeness(self._features, found))

    def _template_features(self, frame: np.ndarray, box: np.ndarray) -> np.ndarray:
        x, y, w, h = box
        size = np.array([w, h]) * (1 + 2 * TEMPLATE_GROWTH)
        crop = _crop(frame, np.array([x + w / 2, y + h / 2]), size, TEMPLATE_SIZE, self._fill)
        return self._template_net.run(image=rgb_blob(crop))["features"]


def _crop(frame: np.ndarray, center: np.ndarray, size: np.ndarray, out: int,
          fill: tuple[float, float, float]) -> np.ndarray:
    """The ``size`` (w, h) window centred on ``center`` (continuous coordinates), resampled to
    ``out`` x ``out``, with ``fill`` outside the frame."""
    return resample_window(frame, (center[0] - 0.5, center[1] - 0.5), (float(size[0]), float(size[1])),
                           (out, out), fill)
