"""Bringing a box inside the frame: ``cut_to_frame`` keeps the part of it that is in view (what
the OpenCV trackers start on, so they start on the subject's visible part, not on a patch beside
it); ``clip_to_frame`` moves the whole box inside, keeping its size."""
from __future__ import annotations

from tracker.runtime.boxes import clip_to_frame, cut_to_frame

WIDTH, HEIGHT = 320, 240


def test_cut_keeps_the_visible_part_of_a_box_over_an_edge() -> None:
    assert cut_to_frame((-16.0, 50.0, 40.0, 40.0), WIDTH, HEIGHT) == (0.0, 50.0, 24.0, 40.0)
    assert cut_to_frame((300.0, 220.0, 40.0, 40.0), WIDTH, HEIGHT) == (300.0, 220.0, 20.0, 20.0)


def test_clip_moves_a_box_over_an_edge_inside_whole() -> None:
    assert clip_to_frame((300.0, 220.0, 40.0, 40.0), WIDTH, HEIGHT) == (280.0, 200.0, 40.0, 40.0)
    assert clip_to_frame((-16.0, -5.0, 40.0, 40.0), WIDTH, HEIGHT) == (0.0, 0.0, 40.0, 40.0)
