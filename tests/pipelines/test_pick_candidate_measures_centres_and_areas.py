"""``pick_candidate``: "central" is the detection whose box *centre* is nearest the frame's centre
(x across, y down), "largest" the one of largest *area*; an unknown pick is refused."""
from __future__ import annotations

import pytest

from pipelines.acquire import pick_candidate
from tracker.detectors import Detection

SIZE = (640, 360)  # centre (320, 180)


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
