"""OTB-protocol scores: centre-error precision and success (IoU) AUC."""
from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from tracker.boxes import Box, center, iou

PRECISION_PX = 20.0
SUCCESS_THRESHOLDS = np.round(np.arange(0.0, 1.0001, 0.05), 2)


def center_errors(predicted: Sequence[Box], truth: Sequence[Box]) -> np.ndarray:
    """Euclidean distance between box centres, frame by frame."""
    _check_lengths(predicted, truth)
    return np.array([np.hypot(*np.subtract(center(p), center(t))) for p, t in zip(predicted, truth)])


def overlaps(predicted: Sequence[Box], truth: Sequence[Box]) -> np.ndarray:
    """IoU of each predicted box with its ground truth."""
    _check_lengths(predicted, truth)
    return np.array([iou(p, t) for p, t in zip(predicted, truth)])


def precision_at(predicted: Sequence[Box], truth: Sequence[Box], px: float = PRECISION_PX) -> float:
    """Fraction of frames whose centre error is at most ``px`` pixels."""
    return float(np.mean(center_errors(predicted, truth) <= px))


def success_curve(predicted: Sequence[Box], truth: Sequence[Box]) -> np.ndarray:
    """Fraction of frames with IoU above each threshold in ``SUCCESS_THRESHOLDS``."""
    ious = overlaps(predicted, truth)
    return np.array([np.mean(ious > t) for t in SUCCESS_THRESHOLDS])


def success_auc(predicted: Sequence[Box], truth: Sequence[Box]) -> float:
    """Mean of the success curve (the OTB success-plot AUC)."""
    return float(np.mean(success_curve(predicted, truth)))


def _check_lengths(predicted: Sequence[Box], truth: Sequence[Box]) -> None:
    if len(predicted) != len(truth) or not truth:
        raise ValueError(f"need equal, non-zero box counts (got {len(predicted)} and {len(truth)})")
