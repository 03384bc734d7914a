"""OTB-protocol scores: centre-error precision and success (IoU) AUC.

Frames without ground truth (a ``NaN`` box, or width or height not above 0: how UAV123, OTB and VOT
mark a subject that is not visible) are left out of both scores, as pytracking's analysis does for
OTB-style datasets (docs/tracker.md): they count neither as hits nor as misses.
"""
from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from tracker.runtime.boxes import Box, center, iou

PRECISION_PX = 20.0
SUCCESS_THRESHOLDS = np.round(np.arange(0.0, 1.0001, 0.05), 2)


def has_truth(box: Box) -> bool:
    """Whether a ground-truth box marks the subject: all values finite, width and height above 0."""
    return bool(np.all(np.isfinite(box)) and box[2] > 0 and box[3] > 0)


def center_errors(predicted: Sequence[Box], truth: Sequence[Box]) -> np.ndarray:
    """Euclidean distance between box centres, frame by frame."""
    _check_lengths(predicted, truth)
    return np.array([np.hypot(*np.subtract(center(p), center(t))) for p, t in zip(predicted, truth)])


def overlaps(predicted: Sequence[Box], truth: Sequence[Box]) -> np.ndarray:
    """IoU of each predicted box with its ground truth."""
    _check_lengths(predicted, truth)
    return np.array([iou(p, t) for p, t in zip(predicted, truth)])


def precision_at(predicted: Sequence[Box], truth: Sequence[Box], px: float = PRECISION_PX) -> float:
    """Fraction of the frames with ground truth whose centre error is at most ``px`` pixels."""
    return float(np.mean(center_errors(*_annotated(predicted, truth)) <= px))


def success_curve(predicted: Sequence[Box], truth: Sequence[Box]) -> np.ndarray:
    """Fraction of the frames with ground truth whose IoU is above each threshold in ``SUCCESS_THRESHOLDS``."""
    ious = overlaps(*_annotated(predicted, truth))
    return np.array([np.mean(ious > t) for t in SUCCESS_THRESHOLDS])


def success_auc(predicted: Sequence[Box], truth: Sequence[Box]) -> float:
    """Mean of the success curve (the OTB success-plot AUC)."""
    return float(np.mean(success_curve(predicted, truth)))


def _annotated(predicted: Sequence[Box], truth: Sequence[Box]) -> tuple[list[Box], list[Box]]:
    """The (predicted, truth) pairs of the frames with ground truth; ValueError when there are none."""
    _check_lengths(predicted, truth)
    pairs = [(p, t) for p, t in zip(predicted, truth) if has_truth(t)]
    if not pairs:
        raise ValueError("no frame has a ground-truth box (all are NaN or empty)")
    kept_predicted, kept_truth = zip(*pairs)
    return list(kept_predicted), list(kept_truth)


def _check_lengths(predicted: Sequence[Box], truth: Sequence[Box]) -> None:
    if len(predicted) != len(truth) or len(truth) == 0:
        raise ValueError(f"need equal, non-zero box counts (got {len(predicted)} and {len(truth)})")
