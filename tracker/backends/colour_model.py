"""Foreground/background colour histograms: how likely each pixel is to belong to the subject.

Complements the correlation filter where the subject deforms or blurs: its colours stay
while its gradients change. Histograms are joint BGR with ``BINS`` levels per channel.
"""
from __future__ import annotations

import cv2
import numpy as np


# 16 levels per channel (OpenCV CSRT's histogram_bins): the subject's ~1000 window pixels fill 16**3
# bins densely enough that a shade not seen yet still counts as the subject; over all 19 shared
# sequences 16 scored higher than Staple's 32 and 8, from the given box and over eight starts
# (docs/tracker-lab.md, V32)
BINS = 16
_SHIFT = 8 - int(np.log2(BINS))


def colour_index(patch: np.ndarray) -> np.ndarray:
    """The joint histogram bin of every pixel of a BGR ``uint8`` patch (a grey one uses one axis)."""
    if patch.ndim == 2:
        return (patch >> _SHIFT).astype(np.int32)
    quantised = (patch >> _SHIFT).astype(np.int32)
    return (quantised[..., 0] * BINS + quantised[..., 1]) * BINS + quantised[..., 2]


class ColourModel:
    """Running foreground and background histograms and the per-pixel subject likelihood."""

    def __init__(self) -> None:
        self._foreground: np.ndarray | None = None
        self._background: np.ndarray | None = None
        self._table: np.ndarray | None = None  # P(subject | bin), made on first use after a lesson

    def learn(self, bins: np.ndarray, foreground: np.ndarray, background: np.ndarray, rate: float) -> None:
        """Fold in the pixels of ``bins`` under the boolean masks (``rate`` 1 restarts)."""
        self._foreground = _fold(self._foreground, bins[foreground], rate)
        self._background = _fold(self._background, bins[background], rate)
        self._table = None

    def likelihood(self, bins: np.ndarray) -> np.ndarray:
        """Per pixel, P(subject | colour) in 0..1 (0 for colours never seen)."""
        if self._foreground is None:
            raise RuntimeError("ColourModel.likelihood() before learn()")
        if self._table is None:  # once per lesson for all bins: cheaper than per pixel
            self._table = self._foreground / (self._foreground + self._background + 1e-6)
        return self._table.take(bins)


def _fold(histogram: np.ndarray | None, pixels: np.ndarray, rate: float) -> np.ndarray:
    """The normalised histogram of ``pixels``' bins folded into ``histogram`` at ``rate`` (updated
    in place: it is the model's own array; ``rate`` 1 or no histogram yet starts afresh)."""
    counts = np.bincount(pixels, minlength=BINS**3).astype(np.float32)
    counts *= 1.0 / max(float(pixels.size), 1.0)
    if histogram is None or rate >= 1.0:
        return counts
    histogram *= 1.0 - rate
    histogram += rate * counts
    return histogram


def box_response(likelihood: np.ndarray, cell: int, box_cells: tuple[int, int]) -> np.ndarray:
    """Mean likelihood of a ``box_cells`` (cols, rows) box centred on every cell of the grid."""
    rows, cols = likelihood.shape[0] // cell, likelihood.shape[1] // cell
    cells = cv2.resize(likelihood.astype(np.float32, copy=False), (cols, rows),
                       interpolation=cv2.INTER_AREA)  # whole cells: each one's exact mean
    return cv2.boxFilter(cells, -1, box_cells, normalize=True, borderType=cv2.BORDER_CONSTANT)
