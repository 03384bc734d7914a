"""Choosing the subject: persistence before a start, camera-motion frames skipped, picks, --roi."""
from __future__ import annotations

import pytest

from pipelines.acquire import StartConfirmer, check_roi_in_frame, parse_roi, pick_candidate
from tracker.detectors import Detection

SIZE = (640, 360)
SUBJECT = Detection((100.0, 100.0, 40.0, 80.0), 1.0)


def moved(d: Detection, dx: float) -> Detection:
    x, y, w, h = d.box
    return Detection((x + dx, y, w, h), d.score)


def test_a_detection_starts_only_after_it_persists():
    confirmer = StartConfirmer(needed=3, window=5)
    assert confirmer.offer([SUBJECT], SIZE) == []
    assert confirmer.offer([], SIZE) == []
    assert confirmer.offer([moved(SUBJECT, 2)], SIZE) == []  # seen twice so far
    assert confirmer.offer([moved(SUBJECT, 4)], SIZE) == [moved(SUBJECT, 4)]


def test_a_one_frame_flicker_never_starts():
    confirmer = StartConfirmer(needed=3, window=5)
    for dx in range(0, 400, 100):  # a different place every frame
        assert confirmer.offer([moved(SUBJECT, dx)], SIZE) == []


def test_frames_where_the_camera_moved_are_skipped():
    everything = Detection((0.0, 0.0, 400.0, 300.0), 0.5)  # motion over half the image
    confirmer = StartConfirmer(needed=3, window=5, max_moving_fraction=0.10)
    for _ in range(5):
        assert confirmer.offer([everything, SUBJECT], SIZE) == []
    started = [confirmer.offer([SUBJECT], SIZE) for _ in range(3)]
    assert started[:2] == [[], []] and started[2] == [SUBJECT]


def test_pick_central_and_largest():
    small_central = Detection((300.0, 160.0, 20.0, 20.0), 1.0)
    large_corner = Detection((0.0, 0.0, 200.0, 200.0), 1.0)
    both = [large_corner, small_central]
    assert pick_candidate(both, SIZE, "central") == small_central
    assert pick_candidate(both, SIZE, "largest") == large_corner
    assert pick_candidate([], SIZE) is None


@pytest.mark.parametrize("text", ["1,2,3", "a,b,c,d", "0,0,0,10", "1,0,5,-5", "inf,0,10,10", "nan,0,10,10",
                                  "1e400,0,10,10", "0,0,inf,10"])  # inf: once an OverflowError
def test_parse_roi_refuses_bad_boxes(text):
    with pytest.raises(ValueError, match="--roi"):
        parse_roi(text)


def test_parse_roi_reads_a_box():
    assert parse_roi("10, 20,30,40") == (10, 20, 30, 40)


def test_a_roi_over_the_edge_is_kept_and_one_mostly_outside_is_refused():
    for roi in ((10, 20, 30, 40), (600, 300, 60, 60), (-10, -20, 60, 60)):  # inside, 2/3 inside, over a corner
        check_roi_in_frame(roi, (640, 360))
    with pytest.raises(ValueError, match="mostly outside the 640x360 frame"):
        check_roi_in_frame((600, 300, 100, 100), (640, 360))
    with pytest.raises(ValueError, match="lies outside"):
        check_roi_in_frame((700, 400, 64, 96), (640, 360))
