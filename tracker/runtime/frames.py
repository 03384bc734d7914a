"""Frame formats: every tracker and detector takes grey (H x W or H x W x 1), BGR and BGRA ``uint8``
frames and converts them here, once, to what it works on; anything else is a ``ValueError``
naming what was given (never an OpenCV error, never a silently misread frame)."""
from __future__ import annotations

import cv2
import numpy as np


def check_frame(frame: np.ndarray) -> np.ndarray:
    """``frame`` as it is when it is a grey, BGR or BGRA ``uint8`` array; ``ValueError`` otherwise."""
    if not isinstance(frame, np.ndarray):
        raise ValueError(f"a frame must be a numpy array, not {type(frame).__name__}")
    if frame.dtype != np.uint8 or not (frame.ndim == 2 or frame.ndim == 3 and frame.shape[2] in (1, 3, 4)):
        raise ValueError(f"a frame must be grey (H x W or H x W x 1), BGR or BGRA uint8, not "
                         f"{' x '.join(map(str, frame.shape)) or 'a scalar'} {frame.dtype}")
    return frame


def as_grey(frame: np.ndarray) -> np.ndarray:
    """A grey (H x W or H x W x 1), BGR or BGRA ``uint8`` frame as H x W grey (an H x W one as it is)."""
    if check_frame(frame).ndim == 2:
        return frame
    if frame.shape[2] == 1:
        return frame[:, :, 0]
    return cv2.cvtColor(frame, cv2.COLOR_BGRA2GRAY if frame.shape[2] == 4 else cv2.COLOR_BGR2GRAY)


def as_bgr(frame: np.ndarray) -> np.ndarray:
    """A grey, BGR or BGRA ``uint8`` frame as BGR (a BGR one as it is)."""
    if check_frame(frame).ndim == 3 and frame.shape[2] == 3:
        return frame
    if frame.ndim == 3 and frame.shape[2] == 4:
        return cv2.cvtColor(frame, cv2.COLOR_BGRA2BGR)
    return cv2.cvtColor(as_grey(frame), cv2.COLOR_GRAY2BGR)


def as_bgr_or_grey(frame: np.ndarray) -> np.ndarray:
    """A grey, BGR or BGRA ``uint8`` frame as BGR or H x W grey, without adding channels (BGR as it is)."""
    if check_frame(frame).ndim == 3 and frame.shape[2] == 4:
        return cv2.cvtColor(frame, cv2.COLOR_BGRA2BGR)
    return frame if frame.ndim == 3 and frame.shape[2] == 3 else as_grey(frame)
