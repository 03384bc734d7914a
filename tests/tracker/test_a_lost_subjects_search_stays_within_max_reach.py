"""The template search for a lost subject widens while it stays unseen, but only to ``max_reach``
box sizes around where it was last: the tracker does not wander off to a lookalike across the
picture (with a detector, candidates are what may take it further)."""
from __future__ import annotations

from tests.tracker.scripted_backend import follow, scripted_tracker, wide_scene
from tracker.runtime.estimate import TrackState

HERE, FAR = (100.0, 220.0, 40.0, 40.0), (520.0, 220.0, 40.0, 40.0)  # 420 px (10.5 box sizes) apart
GONE = 5


def test_a_lookalike_far_away_is_not_taken_for_the_lost_subject() -> None:
    subject, backend = scripted_tracker(lambda n, restarts: (HERE, 0.9) if n < GONE else (None, 0.0))
    frames = wide_scene([HERE] * GONE + [FAR] * 60)
    subject.init(frames[0], HERE, 0.0)
    estimates = follow(subject, frames[1:])
    assert backend.inits == [0]
    assert all(e.state is TrackState.LOST for e in estimates[-40:])
