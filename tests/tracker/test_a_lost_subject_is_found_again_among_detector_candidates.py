"""A subject tracker given a detector: once the subject is LOST, the detector's candidates are
compared with its look, and the tracker restarts on the one that looks like it, even out of
the template search's reach."""
from __future__ import annotations

from tests.tracker.scripted_backend import BackgroundAndSubject, restarted_by_detection, wide_scene
from tracker.runtime.boxes import iou
from tracker.runtime.estimate import TrackState

BEFORE, AFTER = (100.0, 220.0, 40.0, 40.0), (520.0, 220.0, 40.0, 40.0)  # 420 px apart: past max_reach
ELSEWHERE = (300.0, 60.0, 40.0, 40.0)  # a patch of background
GONE, BACK = 5, 21  # the subject is out of the picture on frames GONE..BACK - 1


def test_a_lost_subject_is_restarted_on_the_candidate_that_looks_like_it() -> None:
    frames = wide_scene([BEFORE] * GONE + [None] * (BACK - GONE) + [AFTER] * 5)
    detector = BackgroundAndSubject(ELSEWHERE, AFTER)
    back, inits = restarted_by_detection(frames, GONE, BACK, BEFORE, AFTER, detector)
    assert inits == [0, BACK]
    assert all(e.state is TrackState.TRACKING for e in back)
    assert iou(back[0].box, AFTER) > 0.9
