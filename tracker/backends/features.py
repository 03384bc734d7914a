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


#: The eleven basic colour terms (Berlin and Kay) as sRGB prototypes; a colour's names are its soft
#: assignment to them by distance in CIE Lab, so the subject's colours count in the filter as its
#: gradients do (the idea of Danelljan et al.'s colour attributes, 2014; these prototypes are ours).
COLOUR_NAME_PROTOTYPES = {
    "black": (20, 20, 20), "white": (240, 240, 240), "grey": (128, 128, 128), "red": (200, 30, 30),
    "green": (40, 150, 50), "blue": (30, 60, 200), "yellow": (240, 220, 40), "orange": (240, 140, 30),
    "brown": (120, 70, 30), "pink": (240, 150, 180), "purple": (130, 50, 150),
}
COLOUR_NAMES = len(COLOUR_NAME_PROTOTYPES)
_NAME_WIDTH = 20.0  # Lab units: about the distance between neighbouring prototypes' borders
_NAME_LEVEL_BITS = 5  # 32 levels per channel: the table has 32 ** 3 rows


def colour_name_cells(patch: np.ndarray) -> np.ndarray:
    """Per cell, the mean colour-name probabilities of a BGR (or grey) ``uint8`` patch's pixels:
    ``(H // CELL, W // CELL, COLOUR_NAMES)`` float32, each cell's summing to 1."""
    level = patch.astype(np.int32) >> (8 - _NAME_LEVEL_BITS)
    if patch.ndim == 2:
        bins = level * ((1 << 2 * _NAME_LEVEL_BITS) + (1 << _NAME_LEVEL_BITS) + 1)
    else:
        bins = (level[..., 0] << 2 * _NAME_LEVEL_BITS) + (level[..., 1] << _NAME_LEVEL_BITS) + level[..., 2]
    names = colour_name_table(1 << _NAME_LEVEL_BITS).take(bins, axis=0)
    height, width = bins.shape
    return cv2.resize(names, (width // CELL, height // CELL), interpolation=cv2.INTER_AREA)


@functools.lru_cache(maxsize=4)
def colour_name_table(bins_per_channel: int) -> np.ndarray:
    """Colour-name probabilities ``(bins ** 3, COLOUR_NAMES)`` of every joint BGR bin's centre."""
    levels = (np.arange(bins_per_channel) + 0.5) * (256.0 / bins_per_channel)
    b, g, r = np.meshgrid(levels, levels, levels, indexing="ij")
    bgr = np.stack([b, g, r], axis=-1).reshape(-1, 1, 3).astype(np.float32) / 255.0
    lab = cv2.cvtColor(bgr, cv2.COLOR_BGR2Lab).reshape(-1, 3)
    prototypes = np.array([rgb[::-1] for rgb in COLOUR_NAME_PROTOTYPES.values()], np.float32).reshape(-1, 1, 3)
    centres = cv2.cvtColor(prototypes / 255.0, cv2.COLOR_BGR2Lab).reshape(-1, 3)
    distance = np.square(lab[:, None, :] - centres[None, :, :]).sum(axis=2)
    weights = np.exp(-(distance - distance.min(axis=1, keepdims=True)) / (2 * _NAME_WIDTH**2))
    return (weights / weights.sum(axis=1, keepdims=True)).astype(np.float32)
