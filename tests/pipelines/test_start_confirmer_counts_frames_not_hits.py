"""``StartConfirmer`` counts the *frames* a detection was seen in: several overlapping hits in one
frame (a detector that doubles a face) are one sighting, not a persisting subject."""
from __future__ import annotations

from pipelines.acquire import StartConfirmer
from tracker.detectors import Detection

SIZE = (640, 360)
SUBJECT = Detection((100.0, 100.0, 40.0, 80.0), 1.0)
DOUBLE = Detection((102.0, 101.0, 40.0, 80.0), 0.8)  # the same subject hit twice


def test_two_hits_in_one_frame_are_one_sighting() -> None:
    confirmer = StartConfirmer(needed=3, window=5)
    assert confirmer.offer([SUBJECT, DOUBLE], SIZE) == []
    assert confirmer.offer([SUBJECT], SIZE) == []  # seen in two frames: not yet
    assert confirmer.offer([SUBJECT], SIZE) == [SUBJECT]
