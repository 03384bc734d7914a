"""Choosing the subject: persistence before a start, camera-motion frames skipped, picks, --roi."""
from __future__ import annotations

import numpy as np
import pytest

from pipelines.loop.acquire import StartConfirmer, check_roi_in_frame, parse_roi, pick_candidate
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


# Where subject choice draws its lines: a persistence window of exactly ``window`` frames and a
# --roi kept from half inside the frame on.


@pytest.mark.parametrize("gap, started", [(2, True),    # the first sighting is the window's oldest frame
                                         (3, False)])  # it is six frames back
def test_only_sightings_within_the_window_count(gap: int, started: bool) -> None:
    confirmer = StartConfirmer(needed=3, window=5)
    for frame in [[SUBJECT], [SUBJECT], *[[]] * gap]:
        assert confirmer.offer(frame, SIZE) == []
    assert confirmer.offer([SUBJECT], SIZE) == ([SUBJECT] if started else [])


@pytest.mark.parametrize("roi, kept", [((590, 300, 100, 60), True),    # half inside
                                       ((600, 300, 100, 60), False)])  # 40 % inside
def test_a_roi_is_kept_from_half_inside_the_frame_on(roi: tuple[int, int, int, int], kept: bool) -> None:
    if kept:
        check_roi_in_frame(roi, SIZE)
    else:
        with pytest.raises(ValueError, match="mostly outside"):
            check_roi_in_frame(roi, SIZE)


# A frame is taken as camera motion (and skipped) when the motion detector's boxes *together*
# cover over ``max_moving_fraction`` of it: a shaken camera gives many blobs, none of them large.
SPECKS = [Detection((200.0 + 60 * i, 20.0, 50.0, 50.0), 0.1) for i in range(8)]  # 8 x 1.1 % of the frame


def test_a_frame_of_many_small_blobs_is_skipped() -> None:
    confirmer = StartConfirmer(needed=3, window=5, max_moving_fraction=0.05)
    assert [confirmer.offer([SUBJECT, *SPECKS], SIZE) for _ in range(4)] == [[]] * 4
    assert confirmer.offer([SUBJECT], SIZE) == []  # the shaken frames did not count


# ``pick_candidate``: "central" is the detection whose box *centre* is nearest the frame's centre
# (x across, y down), "largest" the one of largest *area*; an unknown pick is refused.


def test_central_goes_by_the_box_centre_not_its_corner() -> None:
    corner_at_centre = Detection((320.0, 180.0, 200.0, 160.0), 1.0)  # its centre (420, 260)
    centred = Detection((250.0, 110.0, 120.0, 120.0), 1.0)  # its centre (310, 170)
    assert pick_candidate([corner_at_centre, centred], SIZE, "central") == centred


def test_central_measures_across_in_x_and_down_in_y() -> None:
    """A frame wider than tall: the candidate at the centre is picked, not one at (180, 320)'s side."""
    at_centre = Detection((300.0, 160.0, 40.0, 40.0), 1.0)
    at_swapped = Detection((160.0, 300.0, 40.0, 40.0), 1.0)
    assert pick_candidate([at_swapped, at_centre], SIZE, "central") == at_centre


def test_largest_goes_by_area_not_width() -> None:
    wide = Detection((0.0, 0.0, 100.0, 20.0), 1.0)  # 2000 px
    tall = Detection((300.0, 0.0, 60.0, 200.0), 1.0)  # 12000 px
    assert pick_candidate([wide, tall], SIZE, "largest") == tall


def test_an_unknown_pick_is_refused() -> None:
    with pytest.raises(ValueError, match="unknown pick 'biggest'"):
        pick_candidate([Detection((0.0, 0.0, 10.0, 10.0), 1.0)], SIZE, "biggest")


# ``StartConfirmer`` counts the *frames* a detection was seen in: several overlapping hits in one
# frame (a detector that doubles a face) are one sighting, not a persisting subject.
DOUBLE = Detection((102.0, 101.0, 40.0, 80.0), 0.8)  # the same subject hit twice


def test_two_hits_in_one_frame_are_one_sighting() -> None:
    confirmer = StartConfirmer(needed=3, window=5)
    assert confirmer.offer([SUBJECT, DOUBLE], SIZE) == []
    assert confirmer.offer([SUBJECT], SIZE) == []  # seen in two frames: not yet
    assert confirmer.offer([SUBJECT], SIZE) == [SUBJECT]


# ``StartConfirmer`` follows a moving candidate: a detection is matched against the candidate's
# last box moved on at its velocity, so a subject crossing the picture is confirmed on its third
# sighting as a still one is; detections at random places in isolated frames are not.


def at(x: float, y: float = 100.0) -> Detection:
    return Detection((x, y, 40.0, 80.0), 1.0)


@pytest.mark.parametrize("step", [8.0, 15.0, 20.0])  # a fifth to a half of the box's width a frame
def test_a_steady_mover_is_confirmed_on_its_third_sighting(step: float) -> None:
    confirmer = StartConfirmer()
    offered = [confirmer.offer([at(100 + step * i)], SIZE) for i in range(3)]
    assert offered == [[], [], [at(100 + 2 * step)]]


def test_a_mover_missed_in_one_frame_is_confirmed_where_it_went_on_to() -> None:
    confirmer = StartConfirmer()
    offered = [confirmer.offer(frame, SIZE) for frame in ([at(100, 40)], [at(112, 50)], [], [at(136, 70)])]
    assert offered == [[], [], [], [at(136, 70)]]


def test_detections_at_random_places_in_isolated_frames_are_never_confirmed() -> None:
    rng = np.random.default_rng(0)
    confirmer = StartConfirmer()
    for i in range(300):
        frame = [at(rng.uniform(0, 600), rng.uniform(0, 280))] if i % 2 == 0 else []
        assert confirmer.offer(frame, SIZE) == [], i
