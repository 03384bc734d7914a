"""Refinement (``refine_blend``, on for the OpenCV backends): a confident box that sits a little
off the subject is moved part-way onto the best template match near it."""
from __future__ import annotations

import numpy as np

from tests.tracker.scripted_backend import follow, scripted_tracker
from tracker.runtime.boxes import center
from tracker.runtime.estimate import TrackState
from tracker.evaluation.synthetic import render_sequence

OFFSET = 3.0  # px right of the subject (its size 40: within refine_reach's 4 px)


def _x_errors(**settings: float) -> list[float]:
    """The estimate's horizontal error over a moving subject whose backend answers ``OFFSET`` px right of it."""
    seq = render_sequence(frames=25, target=40, speed=2.0, seed=2)
    subject, _ = scripted_tracker(lambda n, restarts: ((seq.boxes[n][0] + OFFSET, *seq.boxes[n][1:]), 0.9),
                                  **settings)
    subject.init(seq.frames[0], seq.boxes[0], 0.0)
    estimates = follow(subject, seq.frames[1:])
    assert all(e.state is TrackState.TRACKING for e in estimates)
    return [center(e.box)[0] - center(truth)[0] for e, truth in zip(estimates, seq.boxes[1:])]


def test_an_offset_box_is_moved_halfway_onto_the_subject() -> None:
    settled = _x_errors()[-10:]
    assert abs(np.mean(settled) - OFFSET / 2) < 0.6, settled  # refine_blend 0.5


def test_without_refinement_the_offset_stays() -> None:
    settled = _x_errors(refine_blend=0.0)[-10:]
    assert abs(np.mean(settled) - OFFSET) < 0.3, settled
