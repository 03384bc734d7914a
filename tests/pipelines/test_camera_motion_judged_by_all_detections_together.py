"""A frame is taken as camera motion (and skipped) when the motion detector's boxes *together*
cover over ``max_moving_fraction`` of it: a shaken camera gives many blobs, none of them large."""
from __future__ import annotations

from pipelines.acquire import StartConfirmer
from tracker.detectors import Detection

SIZE = (640, 360)
SUBJECT = Detection((100.0, 100.0, 40.0, 80.0), 1.0)
SPECKS = [Detection((200.0 + 60 * i, 20.0, 50.0, 50.0), 0.1) for i in range(8)]  # 8 x 1.1 % of the frame


def test_a_frame_of_many_small_blobs_is_skipped() -> None:
    confirmer = StartConfirmer(needed=3, window=5, max_moving_fraction=0.05)
    assert [confirmer.offer([SUBJECT, *SPECKS], SIZE) for _ in range(4)] == [[]] * 4
    assert confirmer.offer([SUBJECT], SIZE) == []  # the shaken frames did not count
