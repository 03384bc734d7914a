"""``dcf``'s subject tracker restarts its backend on a template match only once the subject is lost:
through a few unsure frames the correlation filter usually stays on the subject, and restarting it
there put it on look-alike background (dtb70_mountainbike6 at frame 26, docs/tracker.md)."""
from __future__ import annotations

from tests.tracker.scripted_backend import ScriptedBackend, follow, gives_up, on_truth
from tracker.runtime.estimate import TrackState
from tracker.runtime.registry import make_tracker
from tracker.evaluation.synthetic import render_sequence

GIVES_UP_AT = 8


def test_an_unsure_dcf_is_not_restarted_until_the_subject_is_lost() -> None:
    seq = render_sequence(frames=40, speed=2.0, seed=3)
    subject = make_tracker("dcf")
    backend = ScriptedBackend(gives_up(GIVES_UP_AT, on_truth(seq)))
    subject._backend = backend
    subject.init(seq.frames[0], seq.boxes[0], 0.0)
    estimates = follow(subject, seq.frames[1:])
    lost_after = subject.settings.lost_after_frames
    restart = GIVES_UP_AT + lost_after  # the first miss past lost_after_frames
    assert backend.inits == [0, restart]
    states = [e.state for e in estimates]
    assert states[GIVES_UP_AT - 1:restart - 1] == [TrackState.SEARCHING] * lost_after
    assert states[restart - 1] is TrackState.TRACKING
