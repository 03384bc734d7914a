"""OTB-protocol evaluation: initialise on the first ground-truth box, never re-initialise."""
from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from tracker.boxes import Box, center, from_center
from tracker.datasets import ASSUMED_FPS, Sequence
from tracker.estimate import TargetEstimate, TrackState
from tracker.metrics import precision_at, success_auc


class Trackable(Protocol):
    def init(self, frame: np.ndarray, box: Box, timestamp: float) -> object: ...

    def update(self, frame: np.ndarray, timestamp: float) -> TargetEstimate: ...


@dataclass(frozen=True)
class SequenceResult:
    """Scores of one tracker on one sequence."""

    name: str
    frames: int
    prec20: float
    auc: float
    fps: float
    boxes: list[Box] = field(repr=False, compare=False)
    cpu_fps: float = float("nan")  # frames per second of this process's CPU time (less load-dependent)

    def as_dict(self) -> dict[str, object]:
        return {"sequence": self.name, "frames": self.frames, "prec20": round(self.prec20, 4),
                "auc": round(self.auc, 4), "fps": round(self.fps, 1)}


#: OTB's spatial-robustness starts, as (x shift, y shift, scale) of the first box: shifts in
#: box sizes. A tracker's score from one start is partly luck on footage where small differences
#: grow; the mean over these is steadier.
PERTURBED_STARTS = ((0.1, 0.0, 1.0), (0.0, 0.1, 1.0), (-0.1, -0.1, 1.0), (0.0, 0.0, 1.1), (0.0, 0.0, 0.9),
                    (0.05, -0.05, 1.05), (-0.05, 0.05, 0.95))


def perturbed_box(box: Box, dx: float, dy: float, scale: float) -> Box:
    """``box`` moved by ``dx``, ``dy`` box sizes and scaled about its centre by ``scale``."""
    cx, cy = center(box)
    w, h = box[2], box[3]
    return from_center(cx + dx * w, cy + dy * h, w * scale, h * scale)


def run_sequence(tracker: Trackable, sequence: Sequence,
                 progress: Callable[[int, int], None] | None = None, start: Box | None = None) -> SequenceResult:
    """Track ``sequence`` from ``start`` (default: the first ground-truth box) and score it; a
    ``LOST`` estimate holds the last reported box.

    Only ``update`` is timed (fps of the tracking step), in wall-clock and in process CPU time.
    """
    truth = sequence.groundtruth
    if truth is None:
        raise ValueError(f"{sequence.name}: no ground truth to evaluate against")
    start = truth[0] if start is None else start
    boxes: list[Box] = []
    elapsed = cpu = 0.0
    total = len(sequence)
    for index, frame in enumerate(sequence.frames()):
        timestamp = index / ASSUMED_FPS
        if index == 0:
            tracker.init(frame, start, timestamp)
            boxes.append(start)
        else:
            start, cpu_start = time.perf_counter(), time.process_time()
            estimate = tracker.update(frame, timestamp)
            elapsed += time.perf_counter() - start
            cpu += time.process_time() - cpu_start
            boxes.append(boxes[-1] if estimate.state is TrackState.LOST else estimate.box)
        if progress is not None:
            progress(index + 1, total)
    if len(boxes) != total:
        raise ValueError(f"{sequence.name}: read {len(boxes)} frames, expected {total}")
    fps = (total - 1) / elapsed if elapsed > 0 else float("inf")
    cpu_fps = (total - 1) / cpu if cpu > 0 else float("inf")
    return SequenceResult(sequence.name, total, precision_at(boxes, truth), success_auc(boxes, truth), fps, boxes,
                          cpu_fps)


def summarize(results: list[SequenceResult]) -> dict[str, float]:
    """Mean precision and AUC over sequences, median fps (wall-clock and CPU time)."""
    if not results:
        raise ValueError("no results to summarise")
    return {"sequences": len(results),
            "prec20": round(float(np.mean([r.prec20 for r in results])), 4),
            "auc": round(float(np.mean([r.auc for r in results])), 4),
            "fps": round(float(np.median([r.fps for r in results])), 1),
            "cpu_fps": round(float(np.median([r.cpu_fps for r in results])), 1)}
