"""Re-acquisition by template search: a backend that has left the subject is restarted on the best
template match near the prediction (from the ``reacquire_after_frames``-th miss on, at the
subject's size on its latest confident frame); one that is merely unsure while on the subject is
not, and its weak box still steers the estimate."""
from __future__ import annotations

from tests.tracker.scripted_backend import Answer, follow, gives_up, on_truth, scripted_tracker
from tracker.runtime.boxes import Box, iou
from tracker.runtime.estimate import TargetEstimate, TrackState
from tracker.evaluation.synthetic import render_sequence

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
