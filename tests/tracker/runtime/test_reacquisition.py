"""Finding a lost subject again (tracker/runtime/subject.py): the template search, its restart rules
and the detector's candidates."""
from __future__ import annotations

import numpy as np
import pytest

from tests.tracker.scripted_backend import (
    Answer, BackgroundAndSubject, FPS, ScriptedBackend, follow, gives_up, on_truth, restarted_by_detection,
    scripted_tracker, wide_scene,
)
from tracker.evaluation.synthetic import render_sequence, texture
from tracker.runtime.appearance import AppearanceModel
from tracker.runtime.boxes import Box, iou
from tracker.runtime.estimate import TargetEstimate, TrackState
from tracker.runtime.subject import SubjectTracker


# Re-acquisition by template search: a backend that has left the subject is restarted on the best
# template match near the prediction (from the ``reacquire_after_frames``-th miss on, at the
# subject's size on its latest confident frame); one that is merely unsure while on the subject is
# not, and its weak box still steers the estimate.
GIVES_UP_AT = 8  # the backend answers nothing from this frame until it is restarted
REACQUIRE_AFTER = 3  # TrackerSettings.reacquire_after_frames


def _run_giving_up(**sequence: float) -> tuple[list[TargetEstimate], list[int], list[Box]]:
    """The estimates of a tracker whose backend gives up at ``GIVES_UP_AT`` on a rendered
    sequence, the backend's (re)starts and the true boxes."""
    seq = render_sequence(seed=3, **sequence)
    subject, backend = scripted_tracker(gives_up(GIVES_UP_AT, on_truth(seq)))
    subject.init(seq.frames[0], seq.boxes[0], 0.0)
    return follow(subject, seq.frames[1:]), backend.inits, seq.boxes


def test_a_backend_that_gives_up_is_restarted_on_the_subject() -> None:
    estimates, inits, truth = _run_giving_up(frames=20, speed=3.0)
    restart = GIVES_UP_AT + REACQUIRE_AFTER - 1  # the third miss
    assert inits == [0, restart]
    states = [e.state for e in estimates]
    assert states[GIVES_UP_AT - 1:restart - 1] == [TrackState.SEARCHING] * (REACQUIRE_AFTER - 1)
    assert states[restart - 1:] == [TrackState.TRACKING] * (len(states) - restart + 1)
    assert iou(estimates[restart - 1].box, truth[restart]) > 0.7


def test_a_subject_that_grew_is_restarted_at_its_new_size() -> None:
    estimates, inits, truth = _run_giving_up(frames=40, scale_change=1.6, speed=2.0)
    restart = GIVES_UP_AT + REACQUIRE_AFTER - 1
    assert inits == [0, restart]
    assert estimates[restart - 1].box[2] > 1.1 * truth[0][2]  # it had grown by a sixth by then
    assert iou(estimates[restart - 1].box, truth[restart]) > 0.7


def test_a_box_shrinking_as_the_subject_slides_out_of_sight_does_not_set_the_size_searched_for() -> None:
    """The backend's box loses its leading edge frame by frame (accepted, but no longer confident)
    and then nothing: the search looks for the subject at its last confident size, not at the
    squeezed box's, and restarts the backend on it (at the squeezed size no match is good enough)."""
    seq = render_sequence(frames=20, speed=2.0, seed=3)

    def squeezed(n: int, restarts: int) -> Answer:
        x, y, w, h = (float(v) for v in seq.boxes[n])
        if restarts or n < 8:
            return (x, y, w, h), 0.9
        return ((x, y, w * (1.0 - 0.07 * (n - 7)), h), 0.8) if n < 14 else (None, 0.0)

    subject, backend = scripted_tracker(squeezed)
    subject.init(seq.frames[0], seq.boxes[0], 0.0)
    estimates = follow(subject, seq.frames[1:])
    first_miss = 11  # its box 0.72 as wide as the subject (frame 8's, 0.93 wide, the last confident)
    states = [e.state for e in estimates[:first_miss]]
    assert states == [TrackState.TRACKING] * (first_miss - 1) + [TrackState.SEARCHING]
    restart = first_miss + REACQUIRE_AFTER - 1
    assert backend.inits == [0, restart]
    assert estimates[restart - 1].box[2] > 0.9 * seq.boxes[restart][2]
    assert iou(estimates[restart - 1].box, seq.boxes[restart]) > 0.8


def test_an_unsure_backend_on_the_subject_is_not_restarted_and_still_steers_the_estimate() -> None:
    """A score of 0.2 makes every frame a miss, but the backend's box looks like the subject, so a
    template match cannot beat it by ``reacquire_margin``: no restart (the backend keeps its
    model). The weak boxes still pull the estimate along with the moving subject."""
    seq = render_sequence(frames=13, speed=3.0, seed=3)
    subject, backend = scripted_tracker(on_truth(seq, score=0.2))
    subject.init(seq.frames[0], seq.boxes[0], 0.0)
    estimates = follow(subject, seq.frames[1:])
    assert backend.inits == [0]
    assert all(e.state is TrackState.SEARCHING for e in estimates)
    assert iou(estimates[-1].box, seq.boxes[-1]) > 0.6  # the subject moved 36 px (its size 40)


# The template search for a lost subject widens while it stays unseen, but only to ``max_reach``
# box sizes around where it was last: the tracker does not wander off to a lookalike across the
# picture (with a detector, candidates are what may take it further).
HERE, FAR = (100.0, 220.0, 40.0, 40.0), (520.0, 220.0, 40.0, 40.0)  # 420 px (10.5 box sizes) apart
GONE = 5


def test_a_lookalike_far_away_is_not_taken_for_the_lost_subject() -> None:
    subject, backend = scripted_tracker(lambda n, restarts: (HERE, 0.9) if n < GONE else (None, 0.0))
    frames = wide_scene([HERE] * GONE + [FAR] * 60)
    subject.init(frames[0], HERE, 0.0)
    estimates = follow(subject, frames[1:])
    assert backend.inits == [0]
    assert all(e.state is TrackState.LOST for e in estimates[-40:])


# A template-search restart also asks the backend, when it can score a box (NanoTrack: its
# deep-feature likeness to the subject over the typical one), whether the match looks like the
# subject: a pixel match the backend's own features disown does not restart it.


class JudgingBackend(ScriptedBackend):
    """A scripted backend that scores every box it is asked about at ``likeness``."""

    def __init__(self, answer, likeness: float) -> None:
        super().__init__(answer)
        self._likeness = likeness
        self.asked: list[Box] = []

    def likeness(self, frame, box: Box) -> float:
        self.asked.append(box)
        return self._likeness


@pytest.mark.parametrize("likeness, restarted", [(0.3, False), (0.9, True)])
def test_a_pixel_match_restarts_the_backend_only_if_it_likes_the_box_too(likeness: float, restarted: bool) -> None:
    seq = render_sequence(frames=20, speed=3.0, seed=3)
    backend = JudgingBackend(gives_up(GIVES_UP_AT, on_truth(seq)), likeness)
    subject = SubjectTracker("judging", backend)
    subject.init(seq.frames[0], seq.boxes[0], 0.0)
    estimates = follow(subject, seq.frames[1:])
    assert (len(backend.inits) > 1) is restarted
    assert backend.asked, "the backend was never asked about the match"
    assert (estimates[-1].state is TrackState.TRACKING) is restarted


# The template search must not restart the backend on a patch that only half looks like the
# subject: here one matching the subject's templates at 0.76, over the absolute 0.75 needed but well
# under the 1.0 the subject matched itself at. While the subject is away the tracker keeps searching
# (no `tracking` off the subject, so the gimbal is not steered there), and it restarts on the subject
# itself when it comes back.
SUBJECT: Box = (60.0, 100.0, 40.0, 40.0)
LOOK_ALIKE: Box = (140.0, 100.0, 40.0, 40.0)
AWAY = range(8, 30)  # frames without the subject
FRAMES = 45


class HoldsWhereStarted:
    """A backend that answers the box it was (re)started on, except that its first run gives up
    while the subject is away (a still subject and look-alike: no motion to follow)."""

    name = "holds"

    def __init__(self) -> None:
        self.frame = 0
        self.starts: list[Box] = []

    def init(self, frame: np.ndarray, box: Box) -> None:
        self.starts.append(box)

    def update(self, frame: np.ndarray) -> tuple[Box | None, float]:
        self.frame += 1
        if len(self.starts) == 1 and self.frame >= AWAY.start:
            return None, 0.0
        return self.starts[-1], 0.9


def _frames() -> list[np.ndarray]:
    rng = np.random.default_rng(11)
    background = texture(240, 320, rng, cell=16, contrast=0.35)
    look = texture(40, 40, rng, cell=6, contrast=1.0)
    other = texture(40, 40, rng, cell=6, contrast=1.0)
    half_alike = (0.5 * look + 0.5 * other).astype(np.uint8)
    frames = []
    for i in range(FRAMES):
        frame = background.copy()
        frame[100:140, 140:180] = half_alike
        if i not in AWAY:
            frame[100:140, 60:100] = look
        frames.append(frame)
    return frames


def test_the_look_alike_matches_just_over_the_absolute_restart_score() -> None:
    frames = _frames()
    found = AppearanceModel(frames[0], SUBJECT).search(frames[AWAY.start], SUBJECT, SUBJECT[2:], 4.0)
    assert iou(found.box, LOOK_ALIKE) > 0.9
    assert 0.75 <= found.score <= 0.77


def test_a_half_alike_patch_is_not_taken_for_a_subject_that_matched_itself_well() -> None:
    frames = _frames()
    backend = HoldsWhereStarted()
    subject = SubjectTracker("holds", backend)
    subject.init(frames[0], SUBJECT, 0.0)
    estimates = [subject.update(frame, i / FPS) for i, frame in enumerate(frames[1:], 1)]
    away = [estimates[i - 1] for i in AWAY]
    assert all(e.state is not TrackState.TRACKING for e in away), "tracking while the subject was away"
    assert all(iou(start, LOOK_ALIKE) < 0.3 for start in backend.starts), "restarted on the look-alike"
    back = estimates[AWAY.stop + 5 - 1:]
    assert all(e.state is TrackState.TRACKING and iou(e.box, SUBJECT) > 0.8 for e in back)


# A subject tracker given a detector: once the subject is LOST, the detector's candidates are
# compared with its look, and the tracker restarts on the one that looks like it, even out of
# the template search's reach.
BEFORE, AFTER = (100.0, 220.0, 40.0, 40.0), (520.0, 220.0, 40.0, 40.0)  # 420 px apart: past max_reach
ELSEWHERE = (300.0, 60.0, 40.0, 40.0)  # a patch of background
BACK = 21  # the subject is out of the picture on frames GONE..BACK - 1


def test_a_lost_subject_is_restarted_on_the_candidate_that_looks_like_it() -> None:
    frames = wide_scene([BEFORE] * GONE + [None] * (BACK - GONE) + [AFTER] * 5)
    detector = BackgroundAndSubject(ELSEWHERE, AFTER)
    back, inits = restarted_by_detection(frames, GONE, BACK, BEFORE, AFTER, detector)
    assert inits == [0, BACK]
    assert all(e.state is TrackState.TRACKING for e in back)
    assert iou(back[0].box, AFTER) > 0.9


# A subject started on part of itself (a motion box that caught only its left half) learnt that
# part's look, which the detector's box of the whole subject does not resemble (likeness 0.28 here).
# Once it is lost, the tracker also looks for the subject's templates, at the subject's size, inside
# each detection, and restarts on the part where it is found; a detection of something else still
# does not qualify.
PART = (100.0, 220.0, 20.0, 40.0)  # the left half of the 40 px subject at (100, 220)
WHOLE_AFTER = (520.0, 220.0, 40.0, 40.0)  # the whole subject, 420 px away: past max_reach
PART_AFTER = (520.0, 220.0, 20.0, 40.0)


def test_a_subject_started_on_its_part_is_restarted_on_that_part_of_a_whole_detection() -> None:
    frames = wide_scene([(100.0, 220.0, 40.0, 40.0)] * GONE + [None] * (BACK - GONE) + [WHOLE_AFTER] * 5)
    detector = BackgroundAndSubject(ELSEWHERE, WHOLE_AFTER)
    back, inits = restarted_by_detection(frames, GONE, BACK, PART, PART_AFTER, detector)
    assert inits == [0, BACK]
    assert all(e.state is TrackState.TRACKING for e in back)
    assert iou(back[0].box, PART_AFTER) > 0.9
