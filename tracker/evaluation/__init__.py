"""OTB-protocol evaluation: initialise on the first ground-truth box, never re-initialise."""
from __future__ import annotations

import math
import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from tracker.evaluation.datasets import ASSUMED_FPS, Sequence
from tracker.evaluation.metrics import has_truth, precision_at, success_auc
from tracker.runtime.boxes import Box, center, from_center
from tracker.runtime.estimate import TargetEstimate, TrackState


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
    fps: float  # NaN when no frame was timed (a one-frame sequence)
    boxes: list[Box] = field(repr=False, compare=False)
    cpu_fps: float = float("nan")  # frames per second of this process's CPU time (less load-dependent)

    def as_dict(self) -> dict[str, object]:
        """The row ``gimbaltrack eval --json`` prints: valid JSON, so an unmeasured fps is None (null)."""
        return {"sequence": self.name, "frames": self.frames, "prec20": round(self.prec20, 4),
                "auc": round(self.auc, 4), "fps": _rounded_rate(self.fps)}


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


def first_box(sequence: Sequence) -> Box:
    """The first ground-truth box, where the OTB protocol starts; ValueError when there is no
    ground truth or the first box does not mark the subject (NaN, or width or height not above 0)."""
    if sequence.groundtruth is None:
        raise ValueError(f"{sequence.name}: no ground truth to evaluate against")
    box = sequence.groundtruth[0]
    if not has_truth(box):
        raise ValueError(f"{sequence.name}: the first ground-truth box ({', '.join(f'{v:g}' for v in box)}) "
                         "is missing or empty; the tracker starts on it, so it must have a width and height above 0")
    return box


def run_sequence(tracker: Trackable, sequence: Sequence,
                 progress: Callable[[int, int], None] | None = None, start: Box | None = None) -> SequenceResult:
    """Track ``sequence`` from ``start`` (default: the first ground-truth box) and score it; a
    ``LOST`` estimate holds the last reported box.

    Only ``update`` is timed (fps of the tracking step), in wall-clock and in process CPU time; both
    are NaN for a one-frame sequence. A frame that cannot be read raises ``FrameReadError``.
    """
    given = first_box(sequence)  # also refuses a sequence without ground truth
    truth = sequence.groundtruth
    start = given if start is None else start
    boxes: list[Box] = []
    elapsed = cpu = 0.0
    total = len(sequence)
    for index, frame in enumerate(sequence.frames()):
        timestamp = index / ASSUMED_FPS
        if index == 0:
            tracker.init(frame, start, timestamp)
            boxes.append(start)
        else:
            cpu_start = time.process_time()  # first: reading the CPU clock is slow here (~0.3 ms), and
            wall_start = time.perf_counter()  # must not count in the wall-clock time of the step
            estimate = tracker.update(frame, timestamp)
            elapsed += time.perf_counter() - wall_start
            cpu += time.process_time() - cpu_start
            boxes.append(boxes[-1] if estimate.state is TrackState.LOST else estimate.box)
        if progress is not None:
            progress(index + 1, total)
    return SequenceResult(sequence.name, total, precision_at(boxes, truth), success_auc(boxes, truth),
                          _rate(total - 1, elapsed), boxes, _rate(total - 1, cpu))


def _rate(frames: int, seconds: float) -> float:
    """Frames per second, NaN when nothing was timed."""
    return frames / seconds if frames > 0 and seconds > 0 else float("nan")


def _rounded_rate(fps: float) -> float | None:
    """``fps`` to 0.1 for printing, None when it was not measured (JSON has no NaN or Infinity)."""
    return round(fps, 1) if math.isfinite(fps) else None


def _median_rate(rates: Iterable[float]) -> float | None:
    """The median of the measured rates, rounded as ``_rounded_rate``; None when none was measured."""
    measured = [r for r in rates if math.isfinite(r)]
    return _rounded_rate(float(np.median(measured))) if measured else None


def summarize(results: list[SequenceResult]) -> dict[str, float | None]:
    """Mean precision and AUC over sequences, median fps (wall-clock and CPU time) over the sequences
    where it was measured (None when none was: one-frame sequences only)."""
    if not results:
        raise ValueError("no results to summarise")
    return {"sequences": len(results),
            "prec20": round(float(np.mean([r.prec20 for r in results])), 4),
            "auc": round(float(np.mean([r.auc for r in results])), 4),
            "fps": _median_rate(r.fps for r in results),
            "cpu_fps": _median_rate(r.cpu_fps for r in results)}

