"""The subject's look: normalised grey templates for confidence and re-acquisition search."""
from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from tracker.runtime.boxes import Box, center, clip_to_frame, from_center
from tracker.runtime.frames import as_grey

TEMPLATE_PX = 32


@dataclass(frozen=True)
class Match:
    """Where a search found the subject, and how alike it looks (normalised correlation, 0..1)."""

    box: Box
    score: float


class AppearanceModel:
    """A fixed template from the first frame plus a slowly adapting one.

    Similarity is the better of the two normalised cross-correlations, so the subject may
    turn and deform without its first look being forgotten.
    """

    def __init__(self, frame: np.ndarray, box: Box) -> None:
        self.anchor = cut_patch(frame, box)
        self.recent = self.anchor.copy()

    def similarity(self, patch: np.ndarray) -> float:
        """How much ``patch`` (from :func:`cut_patch`) looks like the subject, 0..1."""
        return max(_ncc(patch, self.anchor), _ncc(patch, self.recent))

    def adapt(self, patch: np.ndarray, rate: float) -> None:
        """Blend ``patch`` (from :func:`cut_patch`) into the adaptive template."""
        cv2.addWeighted(self.recent, 1.0 - rate, patch, rate, 0.0, dst=self.recent)

    def search(self, frame: np.ndarray, around: Box, size: tuple[float, float], reach: float) -> Match:
        """Best match for a ``size`` box within ``reach`` box sizes of ``around``'s centre."""
        w, h = size
        height, width = frame.shape[:2]
        cx, cy = center(around)
        region = clip_to_frame(from_center(cx, cy, w * (1 + 2 * reach), h * (1 + 2 * reach)), width, height)
        rx, ry, rw, rh = (int(round(v)) for v in region)
        if rw < w or rh < h:
            return Match(around, 0.0)
        sx, sy = TEMPLATE_PX / w, TEMPLATE_PX / h
        crop = frame[ry:ry + rh, rx:rx + rw]
        scaled = cv2.resize(crop, (max(TEMPLATE_PX, int(round(rw * sx))), max(TEMPLATE_PX, int(round(rh * sy)))),
                            interpolation=cv2.INTER_AREA)
        grey = as_grey(scaled).astype(np.float32)
        best = Match(around, 0.0)
        for template in (self.anchor, self.recent):
            scores = cv2.matchTemplate(grey, template, cv2.TM_CCOEFF_NORMED)
            _, score, _, (mx, my) = cv2.minMaxLoc(scores)
            if score > best.score:
                best = Match((rx + mx / sx, ry + my / sy, w, h), float(score))
        return best


def cut_patch(frame: np.ndarray, box: Box) -> np.ndarray:
    """The grey template-sized patch under ``box``, as the model compares and learns it."""
    x, y, w, h = box
    w, h = max(w, 2.0), max(h, 2.0)
    crop = cv2.getRectSubPix(frame, (int(round(w)), int(round(h))), (x + w / 2.0, y + h / 2.0))
    return as_grey(cv2.resize(crop, (TEMPLATE_PX, TEMPLATE_PX), interpolation=cv2.INTER_AREA)).astype(np.float32)


def _ncc(a: np.ndarray, b: np.ndarray) -> float:
    score = float(cv2.matchTemplate(a, b, cv2.TM_CCOEFF_NORMED)[0, 0])
    return min(max(score, 0.0), 1.0) if np.isfinite(score) else 0.0
