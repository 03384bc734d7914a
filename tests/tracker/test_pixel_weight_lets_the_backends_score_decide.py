"""``TrackerSettings.pixel_weight``: how much the subject tracker's pixel likeness counts in the
confidence (a turning subject's pixels stop matching its first look while a model still knows it)."""
import numpy as np

from tests.tracker.scripted_backend import ScriptedBackend
from tracker.runtime.estimate import TrackState
from tracker.runtime.subject import SubjectTracker, TrackerSettings

BOX = (100.0, 80.0, 40.0, 40.0)


def _frames():
    rng = np.random.default_rng(1)
    first = rng.integers(0, 255, (240, 320, 3), dtype=np.uint8)
    turned = first.copy()
    turned[80:120, 100:140] = np.rot90(first[80:120, 100:140])  # the subject turned: other pixels
    return first, turned


def _states(weight: float) -> list[TrackState]:
    first, turned = _frames()
    subject = SubjectTracker("scripted", ScriptedBackend(lambda n, restarts: (BOX, 0.9)), None,
                             TrackerSettings(track_confidence=0.1, pixel_weight=weight, refine_blend=0.0))
    subject.init(first, BOX, 0.0)
    return [subject.update(turned, i / 30).state for i in range(1, 6)]


def test_with_the_pixel_likeness_counted_a_turned_subject_is_doubted():
    assert TrackState.SEARCHING in _states(1.0)


def test_with_weight_zero_the_backends_score_alone_decides():
    assert _states(0.0) == [TrackState.TRACKING] * 5
