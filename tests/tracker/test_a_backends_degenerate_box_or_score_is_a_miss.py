"""A backend's degenerate answer (an empty or sub-pixel box, a NaN score with a finite box) is a
miss: no exception, a finite estimate with no confidence, and an empty or sub-pixel box does not
shrink the subject's box. (NaN and infinite boxes: test_subject_tracker.py.)"""
from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

from tests.tracker.scripted_backend import Answer, follow, scripted_tracker
from tracker.runtime.boxes import Box
from tracker.runtime.estimate import TrackState
from tracker.evaluation.synthetic import render_sequence

SEQ = render_sequence(frames=12, seed=4)
GLITCH = range(4, 8)  # the frames the backend answers oddly; it follows the subject on the others

DEGENERATE: dict[str, Callable[[Box], Answer]] = {
    "empty box": lambda box: ((box[0], box[1], 0.0, 0.0), 0.9),
    "sub-pixel box": lambda box: ((box[0], box[1], 0.4, 0.4), 0.9),
    "NaN score": lambda box: (box, float("nan")),
}


def _estimates(odd: Callable[[Box], Answer]) -> list:
    subject, _ = scripted_tracker(lambda n, restarts: odd(SEQ.boxes[n]) if n in GLITCH else (SEQ.boxes[n], 0.9))
    subject.init(SEQ.frames[0], SEQ.boxes[0], 0.0)
    return follow(subject, SEQ.frames[1:])


@pytest.mark.parametrize("kind", DEGENERATE)
def test_a_degenerate_answer_is_a_finite_miss(kind: str) -> None:
    estimates = _estimates(DEGENERATE[kind])
    assert all(np.isfinite([*e.box, *e.velocity, e.confidence]).all() for e in estimates)
    first = estimates[GLITCH[0] - 1]
    assert first.state is TrackState.SEARCHING and first.confidence == 0.0
    assert estimates[-1].state is TrackState.TRACKING


@pytest.mark.parametrize("kind", ["empty box", "sub-pixel box"])
def test_a_degenerate_box_does_not_shrink_the_subjects_box(kind: str) -> None:
    during = _estimates(DEGENERATE[kind])[GLITCH[0] - 1:GLITCH[-1]]
    assert np.ptp([e.box[2:] for e in during] + [SEQ.boxes[0][2:]], axis=0) == pytest.approx((0.0, 0.0), abs=0.5)
