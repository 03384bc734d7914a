"""Once the subject is LOST, its box holds still (both ways) instead of drifting on with the
velocity it had: the gimbal must not chase a subject that is not there."""
from __future__ import annotations

import numpy as np
import pytest

from tests.tracker.scripted_backend import empty_scene, follow, scripted_tracker
from tracker.runtime.estimate import TrackState
from tracker.evaluation.synthetic import render_sequence

GONE_AT = 8  # moving right and down at about 2.4 px a frame when it vanishes


def test_a_lost_subjects_box_and_velocity_stand_still() -> None:
    seq = render_sequence(frames=GONE_AT, speed=3.0, seed=0)
    subject, _ = scripted_tracker(lambda n, restarts: (seq.boxes[n], 0.9) if n < GONE_AT else (None, 0.0))
    subject.init(seq.frames[0], seq.boxes[0], 0.0)
    estimates = follow(subject, seq.frames[1:] + [empty_scene(0)] * 30)
    moving = estimates[GONE_AT - 2]
    assert moving.state is TrackState.TRACKING and min(moving.velocity) > 40.0  # px/s, right and down
    lost = [e for e in estimates if e.state is TrackState.LOST]
    assert len(lost) >= 10
    assert all(e.velocity == (0.0, 0.0) for e in lost)
    assert np.ptp([e.box[:2] for e in lost], axis=0) == pytest.approx((0.0, 0.0), abs=0.5)
