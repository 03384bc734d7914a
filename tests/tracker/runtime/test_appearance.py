"""The subject's look: the adaptive template lets a subject whose look changes slowly (it turns
round, the light changes) stay TRACKING, though it ends up unlike its first look; one frame teaches
it only ``adapt_rate`` of its look; and the first look is never forgotten."""
from __future__ import annotations

import numpy as np

from tests.tracker.scripted_backend import empty_scene, follow, gives_up, scripted_tracker
from tracker.runtime.appearance import AppearanceModel, cut_patch
from tracker.runtime.estimate import TrackState
from tracker.evaluation.synthetic import texture

BOX = (140.0, 100.0, 40.0, 40.0)
FRAMES = 90


def _turning_subject() -> list[np.ndarray]:
    """The subject standing still at ``BOX`` while its look blends from one texture into another."""
    rng = np.random.default_rng(5)
    first, last = (texture(40, 40, rng, cell=6, contrast=1.0).astype(np.float32) for _ in range(2))
    background = empty_scene(0)
    frames = []
    for i in range(FRAMES + 1):
        frame = background.copy()
        share = i / FRAMES
        frame[100:140, 140:180] = ((1 - share) * first + share * last).round().astype(np.uint8)
        frames.append(frame)
    return frames


def test_a_subject_changing_its_look_slowly_stays_tracked() -> None:
    frames = _turning_subject()
    assert AppearanceModel(frames[0], BOX).similarity(cut_patch(frames[-1], BOX)) < 0.3  # a new look
    subject, _ = scripted_tracker(lambda n, restarts: (BOX, 1.0))
    subject.init(frames[0], BOX, 0.0)
    estimates = follow(subject, frames[1:])
    assert all(e.state is TrackState.TRACKING for e in estimates)
    assert min(e.confidence for e in estimates) > 0.6


def test_one_frame_teaches_the_adaptive_template_only_its_share() -> None:
    frames = _turning_subject()
    model = AppearanceModel(frames[0], BOX)
    new_look = cut_patch(frames[-1], BOX)
    model.adapt(new_look, 0.05)
    assert model.similarity(new_look) < 0.5


def test_the_first_look_is_never_forgotten() -> None:
    frames = _turning_subject()
    model = AppearanceModel(frames[0], BOX)
    for _ in range(200):
        model.adapt(cut_patch(frames[-1], BOX), 0.05)
    assert model.similarity(cut_patch(frames[0], BOX)) > 0.99


def test_a_subject_with_a_new_look_is_found_again_by_it() -> None:
    """The template search for a lost subject looks for its recent look too, not only its first."""
    frames = _turning_subject()
    lost_at = FRAMES - 5
    subject, backend = scripted_tracker(gives_up(lost_at, lambda n, restarts: (BOX, 1.0)))
    subject.init(frames[0], BOX, 0.0)
    estimates = follow(subject, frames[1:])
    assert backend.inits == [0, lost_at + 2]  # on the third miss
    assert estimates[-1].state is TrackState.TRACKING
