"""Where subject choice draws its lines: a persistence window of exactly ``window`` frames and a
--roi kept from half inside the frame on."""
from __future__ import annotations

import pytest

from pipelines.acquire import StartConfirmer, check_roi_in_frame
from tracker.detectors import Detection

SIZE = (640, 360)
SUBJECT = Detection((100.0, 100.0, 40.0, 80.0), 1.0)


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
