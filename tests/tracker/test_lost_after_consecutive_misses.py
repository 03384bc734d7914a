"""``lost_after_frames``: the subject tracker reports LOST after that many *consecutive* misses,
and a confident frame or a (re)start counts them afresh."""
from __future__ import annotations

from tests.tracker.scripted_backend import empty_scene, follow, scripted_tracker
from tracker.runtime.boxes import Box
from tracker.runtime.estimate import TargetEstimate, TrackState
from tracker.evaluation.synthetic import render_sequence

SEQ = render_sequence(frames=12, seed=0)
EMPTY = empty_scene(0)  # SEQ's scene without its subject
LOST_AFTER = 15  # TrackerSettings.lost_after_frames


def _states(estimates: list[TargetEstimate]) -> list[TrackState]:
    return [e.state for e in estimates]


def _gone(n: int, restarts: int) -> tuple[Box | None, float]:
    return None, 0.0


def test_lost_on_the_first_miss_past_lost_after_frames() -> None:
    subject, _ = scripted_tracker(_gone)
    subject.init(SEQ.frames[0], SEQ.boxes[0], 0.0)
    states = _states(follow(subject, [EMPTY] * (LOST_AFTER + 3)))
    assert states == [TrackState.SEARCHING] * LOST_AFTER + [TrackState.LOST] * 3


def test_a_confident_frame_between_misses_counts_them_afresh() -> None:
    """Ten misses, the subject seen once, then fifteen more misses: never fifteen in a row."""
    seen_at = 11
    subject, _ = scripted_tracker(lambda n, restarts: (SEQ.boxes[n], 0.9) if n == seen_at else (None, 0.0))
    subject.init(SEQ.frames[0], SEQ.boxes[0], 0.0)
    frames = [EMPTY] * (seen_at - 1) + [SEQ.frames[seen_at]] + [EMPTY] * (LOST_AFTER + 1)
    states = _states(follow(subject, frames))
    assert states[seen_at - 1] is TrackState.TRACKING
    assert states[seen_at:] == [TrackState.SEARCHING] * LOST_AFTER + [TrackState.LOST]


def test_a_restart_after_a_loss_counts_the_misses_afresh() -> None:
    """Started again on a lost subject (as ``gimbaltrack track`` does on a re-detection), the tracker
    searches for ``lost_after_frames`` frames again before it reports LOST."""
    subject, _ = scripted_tracker(_gone)
    subject.init(SEQ.frames[0], SEQ.boxes[0], 0.0)
    assert follow(subject, [EMPTY] * (LOST_AFTER + 5))[-1].state is TrackState.LOST
    start = LOST_AFTER + 6
    assert subject.init(SEQ.frames[0], SEQ.boxes[0], start / 30).state is TrackState.TRACKING
    states = _states(follow(subject, [EMPTY] * (LOST_AFTER + 1), first=start + 1))
    assert states == [TrackState.SEARCHING] * LOST_AFTER + [TrackState.LOST]
