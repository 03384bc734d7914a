"""Box geometry (tracker/runtime/boxes.py): the start box and boxes brought inside the frame."""
from __future__ import annotations

import pytest

from tracker.runtime.boxes import Box, clip_to_frame, cut_to_frame, start_box


# The subject's first box (``start_box``, used by ``SubjectTracker.init``): kept as given while it
# overlaps the frame by any amount, refused once it only touches an edge from outside, is not
# finite or has no width or height, and grown about its centre to 4 px a side when smaller.
WIDTH, HEIGHT = 320, 240


@pytest.mark.parametrize("box", [(319.0, 10.0, 20.0, 20.0), (-19.0, 10.0, 20.0, 20.0),   # a pixel in, right / left
                                 (10.0, 239.0, 20.0, 20.0), (10.0, -19.0, 20.0, 20.0)])  # bottom / top
def test_a_box_overlapping_the_frame_by_a_pixel_is_kept_as_given(box: Box) -> None:
    assert start_box(box, WIDTH, HEIGHT) == box


@pytest.mark.parametrize("box", [(320.0, 10.0, 20.0, 20.0), (-20.0, 10.0, 20.0, 20.0),   # touching right / left
                                 (10.0, 240.0, 20.0, 20.0), (10.0, -20.0, 20.0, 20.0)])  # bottom / top
def test_a_box_only_touching_the_frame_from_outside_is_refused(box: Box) -> None:
    with pytest.raises(ValueError, match="lies outside the 320x240 frame"):
        start_box(box, WIDTH, HEIGHT)


@pytest.mark.parametrize("box", [(float("nan"), 10.0, 20.0, 20.0), (10.0, 10.0, float("inf"), 20.0)])
def test_a_box_that_is_not_finite_is_refused(box: Box) -> None:
    with pytest.raises(ValueError, match="not finite"):
        start_box(box, WIDTH, HEIGHT)


def test_a_tiny_box_grows_about_its_centre_to_the_minimum_size() -> None:
    assert start_box((100.0, 50.0, 1.0, 6.0), WIDTH, HEIGHT) == (98.5, 50.0, 4.0, 6.0)


@pytest.mark.parametrize("box", [(100.0, 50.0, -20.0, 20.0), (100.0, 50.0, 20.0, 0.0)])
def test_a_box_without_width_or_height_is_refused(box: Box) -> None:
    """Once grown silently into a 4 px box (a swapped corner, x2 < x1, gave a tracker on nothing)."""
    with pytest.raises(ValueError, match="needs a width and height above 0"):
        start_box(box, WIDTH, HEIGHT)


# Bringing a box inside the frame: ``cut_to_frame`` keeps the part of it that is in view (what
# the OpenCV trackers start on, so they start on the subject's visible part, not on a patch beside
# it); ``clip_to_frame`` moves the whole box inside, keeping its size.


def test_cut_keeps_the_visible_part_of_a_box_over_an_edge() -> None:
    assert cut_to_frame((-16.0, 50.0, 40.0, 40.0), WIDTH, HEIGHT) == (0.0, 50.0, 24.0, 40.0)
    assert cut_to_frame((300.0, 220.0, 40.0, 40.0), WIDTH, HEIGHT) == (300.0, 220.0, 20.0, 20.0)


def test_clip_moves_a_box_over_an_edge_inside_whole() -> None:
    assert clip_to_frame((300.0, 220.0, 40.0, 40.0), WIDTH, HEIGHT) == (280.0, 200.0, 40.0, 40.0)
    assert clip_to_frame((-16.0, -5.0, 40.0, 40.0), WIDTH, HEIGHT) == (0.0, 0.0, 40.0, 40.0)
