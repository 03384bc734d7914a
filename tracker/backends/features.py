"""Cell features for the correlation filters: oriented gradients (HOG-like) plus grey level.

Works on a batch of grey images at once, so the scale filter's samples cost one call.
Per cell (``CELL`` x ``CELL`` pixels): 18 contrast-sensitive orientation bins, the 9
contrast-insensitive bins they fold into, both normalised by the gradient energy of the
surrounding 3 x 3 cells and truncated, and the cell's mean grey level, centred on zero.
"""
from __future__ import annotations

import functools

import cv2
import numpy as np

from tracker.runtime.frames import as_grey

CELL = 4
SIGNED_BINS = 18
CHANNELS = SIGNED_BINS + SIGNED_BINS // 2 + 1
_TRUNCATE = 0.2


def cell_features(grey: np.ndarray) -> np.ndarray:
    """Features of ``grey`` (``(n, H, W)`` float32, 0..1; H and W multiples of ``CELL``).

    Returns ``(n, H // CELL, W // CELL, CHANNELS)`` float32.
    """
    n, height, width = grey.shape
    gh, gw = height // CELL, width // CELL
    gx = np.zeros_like(grey)
    gy = np.zeros_like(grey)
    gx[:, :, 1:-1] = grey[:, :, 2:] - grey[:, :, :-2]
    gy[:, 1:-1, :] = grey[:, 2:, :] - grey[:, :-2, :]
    magnitude, angle = cv2.cartToPolar(gx.reshape(-1, width), gy.reshape(-1, width))  # angle in 0..2 pi
    position = angle * np.float32(SIGNED_BINS / (2 * np.pi))
    low = position.astype(np.int32)
    to_high = magnitude * (position - low)
    to_low = magnitude - to_high
    low[low >= SIGNED_BINS] = 0
    high = low + 1
    high[high == SIGNED_BINS] = 0
    cell = _cell_index(n, height, width)
    size = n * gh * gw * SIGNED_BINS
    signed = (np.bincount((cell + low).ravel(), to_low.ravel(), size)
              + np.bincount((cell + high).ravel(), to_high.ravel(), size))
    signed = signed.reshape(n, gh, gw, SIGNED_BINS).astype(np.float32)
    unsigned = signed[..., :SIGNED_BINS // 2] + signed[..., SIGNED_BINS // 2:]
    scale = (1.0 / np.sqrt(_neighbourhood_sum(np.square(unsigned).sum(axis=3)) + 1e-4))[..., None]
    grey_level = cv2.resize(grey.reshape(n * height, width), (gw, n * gh), interpolation=cv2.INTER_AREA)
    grey_level = grey_level.reshape(n, gh, gw, 1) - 0.5
    return np.concatenate([np.minimum(signed * scale, _TRUNCATE), np.minimum(unsigned * scale, _TRUNCATE),
                           grey_level], axis=3).astype(np.float32, copy=False)


def unit_grey(image: np.ndarray) -> np.ndarray:
    """A BGR or grey ``uint8`` image as grey float32 in 0..1, as ``cell_features`` takes it."""
    return as_grey(image).astype(np.float32) * (1.0 / 255.0)


def _neighbourhood_sum(energy: np.ndarray) -> np.ndarray:
    """Each cell's sum over its 3 x 3 neighbourhood within its own image (edges replicated)."""
    rows = energy * 3.0
    rows[:, 1:] += energy[:, :-1] - energy[:, 1:]
    rows[:, :-1] += energy[:, 1:] - energy[:, :-1]
    total = rows * 3.0
    total[:, :, 1:] += rows[:, :, :-1] - rows[:, :, 1:]
    total[:, :, :-1] += rows[:, :, 1:] - rows[:, :, :-1]
    return total


@functools.lru_cache(maxsize=32)
def _cell_index(n: int, height: int, width: int) -> np.ndarray:
    """Each pixel's first histogram slot: (image, cell row, cell column) x bins, as ``(n * H, W)``."""
    gh, gw = height // CELL, width // CELL
    index = (np.arange(n)[:, None, None] * (gh * gw) + (np.arange(height) // CELL)[None, :, None] * gw
             + (np.arange(width) // CELL)[None, None, :]) * SIGNED_BINS
    return index.reshape(n * height, width).astype(np.int32)
