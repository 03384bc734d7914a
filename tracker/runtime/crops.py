"""Cutting a window out of an image and resampling it to a fixed size in one warp."""
from __future__ import annotations

from collections.abc import Sequence

import cv2
import numpy as np


def resample_window(image: np.ndarray, center: Sequence[float], size: Sequence[float], out: tuple[int, int],
                    fill: tuple[float, float, float] | None = None) -> np.ndarray:
    """The ``size`` (w, h) window centred on ``center`` (pixel-index coordinates: pixel i is centred
    on i), resampled to ``out`` (w, h) by one bilinear ``cv2.warpAffine``. Outside the image the
    border is replicated, or ``fill`` where given."""
    step_x, step_y = size[0] / out[0], size[1] / out[1]
    matrix = np.array([[step_x, 0.0, center[0] + (0.5 - out[0] / 2) * step_x],
                       [0.0, step_y, center[1] + (0.5 - out[1] / 2) * step_y]])
    border = cv2.BORDER_REPLICATE if fill is None else cv2.BORDER_CONSTANT
    return cv2.warpAffine(image, matrix, out, flags=cv2.INTER_LINEAR | cv2.WARP_INVERSE_MAP,
                          borderMode=border, borderValue=fill or 0)
