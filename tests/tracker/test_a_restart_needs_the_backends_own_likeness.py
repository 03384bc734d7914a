"""A template-search restart also asks the backend, when it can score a box (NanoTrack: its
deep-feature likeness to the subject over the typical one), whether the match looks like the
subject: a pixel match the backend's own features disown does not restart it."""
from __future__ import annotations

import pytest

from tests.tracker.scripted_backend import ScriptedBackend, follow, gives_up, on_truth
from tracker.runtime.boxes import Box
from tracker.runtime.estimate import TrackState
from tracker.runtime.subject import SubjectTracker
from tracker.evaluation.synthetic import render_sequence

GIVES_UP_AT = 8  # the backend answers nothing from this frame until it is restarted


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
