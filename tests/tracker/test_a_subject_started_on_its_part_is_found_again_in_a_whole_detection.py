"""A subject started on part of itself (a motion box that caught only its left half) learnt that
part's look, which the detector's box of the whole subject does not resemble (likeness 0.28 here).
Once it is lost, the tracker also looks for the subject's templates, at the subject's size, inside
each detection, and restarts on the part where it is found; a detection of something else still
does not qualify."""
from __future__ import annotations

from tests.tracker.scripted_backend import BackgroundAndSubject, restarted_by_detection, wide_scene
from tracker.runtime.boxes import iou
from tracker.runtime.estimate import TrackState

PART = (100.0, 220.0, 20.0, 40.0)  # the left half of the 40 px subject at (100, 220)
WHOLE_AFTER = (520.0, 220.0, 40.0, 40.0)  # the whole subject, 420 px away: past max_reach
PART_AFTER = (520.0, 220.0, 20.0, 40.0)
ELSEWHERE = (300.0, 60.0, 40.0, 40.0)  # a patch of background
GONE, BACK = 5, 21  # the subject is out of the picture on frames GONE..BACK - 1


def test_a_subject_started_on_its_part_is_restarted_on_that_part_of_a_whole_detection() -> None:
    frames = wide_scene([(100.0, 220.0, 40.0, 40.0)] * GONE + [None] * (BACK - GONE) + [WHOLE_AFTER] * 5)
    detector = BackgroundAndSubject(ELSEWHERE, WHOLE_AFTER)
    back, inits = restarted_by_detection(frames, GONE, BACK, PART, PART_AFTER, detector)
    assert inits == [0, BACK]
    assert all(e.state is TrackState.TRACKING for e in back)
    assert iou(back[0].box, PART_AFTER) > 0.9
