"""Foreground/background colour histograms: how likely each pixel is to belong to the subject.

Complements the correlation filter where the subject deforms or blurs: its colours stay
while its gradients change. Histograms are joint BGR with ``BINS`` levels per channel.
"""
from __future__ import annotations

import cv2
import numpy as np

from tracker.correlation import running_average

BINS = 32
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

    def learn(self, bins: np.ndarray, foreground: np.ndarray, background: np.ndarray, rate: float) -> None:
        """Fold in the pixels of ``bins`` under the boolean masks (``rate`` 1 restarts)."""
        size = BINS**3
        fg = np.bincount(bins[foreground], minlength=size).astype(np.float32)
        bg = np.bincount(bins[background], minlength=size).astype(np.float32)
        self._foreground = running_average(self._foreground, fg / max(fg.sum(), 1.0), rate)
        self._background = running_average(self._background, bg / max(bg.sum(), 1.0), rate)

    def likelihood(self, bins: np.ndarray) -> np.ndarray:
        """Per pixel, P(subject | colour) in 0..1 (0 for colours never seen)."""
        if self._foreground is None:
            raise RuntimeError("ColourModel.likelihood() before learn()")
        fg = self._foreground[bins]
        bg = self._background[bins]
        return fg / (fg + bg + 1e-6)


def box_response(likelihood: np.ndarray, cell: int, box_cells: tuple[int, int]) -> np.ndarray:
    """Mean likelihood of a ``box_cells`` (cols, rows) box centred on every cell of the grid."""
    rows, cols = likelihood.shape[0] // cell, likelihood.shape[1] // cell
    cells = likelihood.reshape(rows, cell, cols, cell).mean(axis=(1, 3)).astype(np.float32)
    return cv2.boxFilter(cells, -1, box_cells, normalize=True, borderType=cv2.BORDER_CONSTANT)
