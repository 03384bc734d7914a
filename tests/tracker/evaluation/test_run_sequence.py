"""OTB-protocol details of ``run_sequence`` beyond the scores: what a lost frame scores, the
tracker's clock, the tracking rates and the progress calls."""
from pathlib import Path

import cv2
import numpy as np
import pytest

from tracker import evaluation
from tracker.runtime.boxes import Box
from tracker.evaluation.datasets import ASSUMED_FPS, Sequence
from tracker.runtime.estimate import TargetEstimate, TrackState
from tracker.evaluation import run_sequence
from tracker.evaluation.synthetic import render_sequence


def _sequence(folder: Path, frames: int) -> Sequence:
    seq = render_sequence(frames=frames, seed=0)
    paths = tuple(folder / f"{i}.png" for i in range(frames))
    for path, frame in zip(paths, seq.frames):
        cv2.imwrite(str(path), frame)
    return Sequence("synthetic", frame_paths=paths, groundtruth=tuple(seq.boxes))


class _LosesItOnTheThirdFrame:
    """Reports a box 5 px right of the start, then LOST (with a box far away) from frame 3 on;
    records the timestamps it is given."""

    def __init__(self) -> None:
        self.timestamps: list[float] = []

    def init(self, frame: np.ndarray, box: Box, timestamp: float) -> None:
        self.box, self.frames = (box[0] + 5.0, box[1], box[2], box[3]), 0
        self.timestamps.append(timestamp)

    def update(self, frame: np.ndarray, timestamp: float) -> TargetEstimate:
        self.timestamps.append(timestamp)
        self.frames += 1
        if self.frames >= 2:
            return TargetEstimate((900.0, 900.0, 1.0, 1.0), (0.0, 0.0), 0.0, TrackState.LOST, timestamp, 0)
        return TargetEstimate(self.box, (0.0, 0.0), 0.9, TrackState.TRACKING, timestamp, 0)


class _TenthOfASecondPerUpdate:
    """Stands in for ``time`` in tracker.evaluation: each clock reads 0.1 s after its own last
    reading, so each timed ``update`` takes 0.1 s of wall-clock and of CPU time."""

    def __init__(self) -> None:
        self.wall = self.cpu = 0.0

    def perf_counter(self) -> float:
        self.wall += 0.1
        return self.wall

    def process_time(self) -> float:
        self.cpu += 0.1
        return self.cpu


def test_a_lost_frame_holds_the_last_reported_box(tmp_path: Path) -> None:
    sequence = _sequence(tmp_path, 5)
    tracker = _LosesItOnTheThirdFrame()
    result = run_sequence(tracker, sequence)
    assert result.boxes[0] == sequence.groundtruth[0]
    assert result.boxes[1:] == [tracker.box] * 4


def test_the_tracker_is_given_frame_times_at_the_assumed_rate(tmp_path: Path) -> None:
    tracker = _LosesItOnTheThirdFrame()
    run_sequence(tracker, _sequence(tmp_path, 4))
    assert ASSUMED_FPS == 30.0
    assert tracker.timestamps == pytest.approx([0.0, 1 / 30, 2 / 30, 3 / 30])


def test_rates_count_the_updates_not_the_initialising_frame(tmp_path: Path,
                                                            monkeypatch: pytest.MonkeyPatch) -> None:
    """Five frames: one ``init`` (untimed) and four updates of 0.1 s each, so 10 frames per second."""
    monkeypatch.setattr(evaluation, "time", _TenthOfASecondPerUpdate())
    result = run_sequence(_LosesItOnTheThirdFrame(), _sequence(tmp_path, 5))
    assert result.fps == pytest.approx(10.0) and result.cpu_fps == pytest.approx(10.0)


def test_progress_counts_every_frame_up_to_the_total(tmp_path: Path) -> None:
    calls: list[tuple[int, int]] = []
    run_sequence(_LosesItOnTheThirdFrame(), _sequence(tmp_path, 4),
                 progress=lambda done, total: calls.append((done, total)))
    assert calls == [(1, 4), (2, 4), (3, 4), (4, 4)]
