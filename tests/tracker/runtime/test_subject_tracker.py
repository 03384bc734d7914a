"""The subject tracker on rendered sequences: following, scale, loss and re-acquisition."""
from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
import pytest

from tests.tracker.scripted_backend import Answer, ScriptedBackend, empty_scene, follow, scripted_tracker
from tracker.evaluation.metrics import success_auc
from tracker.evaluation.synthetic import render_sequence, texture
from tracker.runtime.boxes import Box, center, iou
from tracker.runtime.estimate import TargetEstimate, TrackState
from tracker.runtime.registry import available_trackers, make_tracker
from tracker.runtime.subject import SubjectTracker, TrackerSettings


FPS = 30.0


def _track(name, seq, model_dir=None):
    subject = make_tracker(name, model_dir)
    first = subject.init(seq.frames[0], seq.boxes[0], 0.0)
    estimates = [first] + [subject.update(f, i / FPS) for i, f in enumerate(seq.frames[1:], 1)]
    return estimates


def test_available_trackers_lists_default_and_backends():
    names = available_trackers()
    assert names[0] == "default"
    assert {"dcf", "nanotrack", "csrt-fast", "csrt", "kcf", "mil", "nano"} <= set(names)


@pytest.mark.parametrize("name", ["default", "csrt-fast"])
def test_follows_a_moving_target(name):
    seq = render_sequence(frames=60, seed=4)
    estimates = _track(name, seq)
    assert success_auc([e.box for e in estimates], seq.boxes) > 0.7
    assert all(e.state is TrackState.TRACKING for e in estimates)
    assert [e.frame_index for e in estimates] == list(range(60))


def test_velocity_is_in_pixels_per_second():
    seq = render_sequence(frames=40, speed=3.0, seed=5)
    # One frame's velocity follows the backend's per-frame box jitter; the units show in its
    # mean over the last half second.
    vx = np.mean([e.velocity[0] for e in _track("default", seq)[-15:]])
    assert vx == pytest.approx(3.0 * FPS, rel=0.2)


@pytest.mark.parametrize("name", ["default", "csrt-fast"])
@pytest.mark.parametrize("scale_change", [1.6, 0.7])
def test_follows_scale_change(name, scale_change):
    seq = render_sequence(frames=60, scale_change=scale_change, seed=2)
    last = _track(name, seq)[-1]
    assert last.box[2] == pytest.approx(seq.boxes[-1][2], rel=0.25)


def test_full_occlusion_is_reported_and_the_target_reacquired():
    seq = render_sequence(frames=80, occlusion=(25, 45), seed=1)
    estimates = _track("default", seq)
    hidden = [i for i, v in enumerate(seq.visible) if not v]
    late_hidden = hidden[len(hidden) // 2:]
    assert all(estimates[i].state is not TrackState.TRACKING for i in late_hidden)
    assert max(estimates[i].confidence for i in late_hidden) < 0.3
    assert any(estimates[i].state is TrackState.LOST for i in hidden)
    # Back on the subject within 10 frames of it reappearing, and staying there.
    back = hidden[-1] + 10
    assert all(iou(e.box, b) > 0.5 for e, b in zip(estimates[back:], seq.boxes[back:]))
    assert all(e.state is TrackState.TRACKING for e in estimates[-10:])
    assert np.mean([e.confidence for e in estimates[-10:]]) > 0.5


def test_lost_box_does_not_drift_away():
    seq = render_sequence(frames=70, occlusion=(20, 60), seed=6)
    estimates = _track("default", seq)
    lost = [e for e in estimates if e.state is TrackState.LOST]
    assert lost and np.ptp([e.box[0] for e in lost]) < 5


def test_unknown_tracker_and_missing_model_files(tmp_path):
    with pytest.raises(ValueError, match="unknown tracker 'nope'"):
        make_tracker("nope")
    for name in ("nano", "nanotrack"):
        with pytest.raises(FileNotFoundError, match="nanotrack_backbone"):
            make_tracker(name, tmp_path)
    with pytest.raises(FileNotFoundError, match="model directory"):
        make_tracker("nano")


def test_update_before_init_is_an_error():
    with pytest.raises(RuntimeError, match="before init"):
        make_tracker().update(np.zeros((10, 10, 3), np.uint8), 0.0)


def test_default_without_model_files_is_nanovit(tmp_path):
    assert make_tracker("default", tmp_path).name == "nanovit"


def test_nanotrack_v2_follows_on_the_shared_model_files_and_the_default_stays_nanovit(shared_data):
    models = shared_data / "models"
    assert make_tracker("default", models).name == "nanovit"
    seq = render_sequence(frames=50, seed=7)
    estimates = _track("nanotrack", seq, models)
    assert success_auc([e.box for e in estimates], seq.boxes) > 0.6


class _GlitchingBackend:
    """A backend that follows the rendered subject but answers NaN on frames 10 and 11."""

    name = "glitching"

    def __init__(self, boxes):
        self._boxes = boxes
        self._frame = 0  # the sequence's frame, also across re-initialisations

    def init(self, frame, box):
        pass

    def update(self, frame):
        self._frame += 1
        if self._frame in (10, 11):
            return (float("nan"), 5.0, float("inf"), 10.0), float("nan")
        return tuple(float(v) for v in self._boxes[self._frame]), 0.9


def test_a_backends_numerical_failure_is_a_miss_not_a_measurement():
    from tracker.runtime.subject import SubjectTracker

    seq = render_sequence(frames=30, seed=4)
    subject = SubjectTracker("glitching", _GlitchingBackend(seq.boxes))
    subject.init(seq.frames[0], seq.boxes[0], 0.0)
    estimates = [subject.update(f, i / FPS) for i, f in enumerate(seq.frames[1:], 1)]
    assert all(np.isfinite(e.box).all() and np.isfinite(e.velocity).all() and np.isfinite(e.confidence)
               for e in estimates)
    assert [e.state for e in estimates[9:11]] == [TrackState.SEARCHING] * 2
    assert estimates[-1].state is TrackState.TRACKING and iou(estimates[-1].box, seq.boxes[-1]) > 0.7


def test_the_default_tracker_stays_lost_once_the_subject_has_gone():
    """With the subject gone for good, the backend's score must not recover on the background
    (its typical peak used to sink to the background's level within ~60 frames)."""
    seq = render_sequence(frames=20, speed=2.0)
    background = texture(240, 320, np.random.default_rng(0), cell=16, contrast=0.35)  # the scene, no subject
    subject = make_tracker("default")
    subject.init(seq.frames[0], seq.boxes[0], 0.0)
    for i, frame in enumerate(seq.frames[1:], 1):
        subject.update(frame, i / FPS)
    states = [subject.update(background, i / FPS).state for i in range(20, 200)]
    assert TrackState.LOST in states
    assert TrackState.TRACKING not in states[states.index(TrackState.LOST):]


@pytest.mark.parametrize("name", ["dcf", "nanotrack3", "csrt-fast", "mil"])
def test_a_start_box_over_the_frame_edge_is_followed_where_it_is(name):
    """A subject half out of the picture is started on as given (the trackers that need a box
    inside get the visible part), not on a patch moved inside the frame."""
    seq = render_sequence(frames=30, speed=3.0)
    cut = 60  # the frame's left 60 px removed: the first box reaches 16 px over the left edge
    frames = [np.ascontiguousarray(f[:, cut:]) for f in seq.frames]
    truth = [(b[0] - cut, b[1], b[2], b[3]) for b in seq.boxes]
    assert truth[0][0] < 0
    subject = make_tracker(name)
    first = subject.init(frames[0], truth[0], 0.0)
    boxes = [first.box] + [subject.update(f, i / FPS).box for i, f in enumerate(frames[1:], 1)]
    errors = [abs(center(b)[0] - center(t)[0]) for b, t in zip(boxes, truth)]
    assert first.box == pytest.approx(truth[0])
    if name == "dcf":
        assert success_auc(boxes, truth) > 0.8  # 0.44 when the box was moved inside
        assert max(errors) < 4  # 16 px when moved
    else:  # MIL crashed on a box over the edge; nanotrack3's box narrows to the part in view
        assert max(errors) < 20


def test_a_start_box_off_the_frame_is_refused():
    frame = render_sequence(frames=1).frames[0]
    with pytest.raises(ValueError, match="outside"):
        make_tracker("default").init(frame, (330, 10, 20, 20), 0.0)


# ``TargetEstimate.found``: the subject is in hand only while it is tracked.
@pytest.mark.parametrize("state", list(TrackState))
def test_found_is_true_for_tracking_only(state: TrackState) -> None:
    estimate = TargetEstimate((10.0, 20.0, 30.0, 40.0), (0.0, 0.0), 0.5, state, 1.0, 3)
    assert estimate.found is (state is TrackState.TRACKING)
    assert estimate.center == (25.0, 40.0)


# A frame's timestamp is the Kalman filter's clock: None, NaN or a string is refused by name (None
# was a bare TypeError from ``update``; ``init`` took both).
@pytest.mark.parametrize("timestamp", [None, math.nan, math.inf, "0.1", True])
def test_a_timestamp_that_is_not_a_finite_number_is_refused(timestamp: object) -> None:
    seq = render_sequence(frames=2, seed=1)
    tracker = make_tracker("dcf")
    with pytest.raises(ValueError, match="timestamp must be a finite number of seconds"):
        tracker.init(seq.frames[0], seq.boxes[0], timestamp)  # type: ignore[arg-type]
    tracker.init(seq.frames[0], seq.boxes[0], np.float64(0.0))
    with pytest.raises(ValueError, match="timestamp must be a finite number of seconds"):
        tracker.update(seq.frames[1], timestamp)  # type: ignore[arg-type]
    assert all(math.isfinite(v) for v in tracker.update(seq.frames[1], 1 / 30).box)


# A backend's degenerate answer (an empty or sub-pixel box, a NaN score with a finite box) is a
# miss: no exception, a finite estimate with no confidence, and an empty or sub-pixel box does not
# shrink the subject's box. (NaN and infinite boxes: test_subject_tracker.py.)
GLITCH_SEQ = render_sequence(frames=12, seed=4)
GLITCH = range(4, 8)  # the frames the backend answers oddly; it follows the subject on the others

DEGENERATE: dict[str, Callable[[Box], Answer]] = {
    "empty box": lambda box: ((box[0], box[1], 0.0, 0.0), 0.9),
    "sub-pixel box": lambda box: ((box[0], box[1], 0.4, 0.4), 0.9),
    "NaN score": lambda box: (box, float("nan")),
}


def _estimates(odd: Callable[[Box], Answer]) -> list:
    subject, _ = scripted_tracker(
        lambda n, restarts: odd(GLITCH_SEQ.boxes[n]) if n in GLITCH else (GLITCH_SEQ.boxes[n], 0.9))
    subject.init(GLITCH_SEQ.frames[0], GLITCH_SEQ.boxes[0], 0.0)
    return follow(subject, GLITCH_SEQ.frames[1:])


@pytest.mark.parametrize("kind", DEGENERATE)
def test_a_degenerate_answer_is_a_finite_miss(kind: str) -> None:
    estimates = _estimates(DEGENERATE[kind])
    assert all(np.isfinite([*e.box, *e.velocity, e.confidence]).all() for e in estimates)
    first = estimates[GLITCH[0] - 1]
    assert first.state is TrackState.SEARCHING and first.confidence == 0.0
    assert estimates[-1].state is TrackState.TRACKING


@pytest.mark.parametrize("kind", ["empty box", "sub-pixel box"])
def test_a_degenerate_box_does_not_shrink_the_subjects_box(kind: str) -> None:
    during = _estimates(DEGENERATE[kind])[GLITCH[0] - 1:GLITCH[-1]]
    assert np.ptp([e.box[2:] for e in during] + [GLITCH_SEQ.boxes[0][2:]], axis=0) == pytest.approx((0.0, 0.0), abs=0.5)


# ``lost_after_frames``: the subject tracker reports LOST after that many *consecutive* misses,
# and a confident frame or a (re)start counts them afresh.
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


# Once the subject is LOST, its box holds still (both ways) instead of drifting on with the
# velocity it had: the gimbal must not chase a subject that is not there.
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


# ``TrackerSettings.pixel_weight``: how much the subject tracker's pixel likeness counts in the
# confidence (a turning subject's pixels stop matching its first look while a model still knows it).
BOX = (100.0, 80.0, 40.0, 40.0)


def _frames():
    rng = np.random.default_rng(1)
    first = rng.integers(0, 255, (240, 320, 3), dtype=np.uint8)
    turned = first.copy()
    turned[80:120, 100:140] = np.rot90(first[80:120, 100:140])  # the subject turned: other pixels
    return first, turned


def _weighted_states(weight: float) -> list[TrackState]:
    first, turned = _frames()
    subject = SubjectTracker("scripted", ScriptedBackend(lambda n, restarts: (BOX, 0.9)), None,
                             TrackerSettings(track_confidence=0.1, pixel_weight=weight, refine_blend=0.0))
    subject.init(first, BOX, 0.0)
    return [subject.update(turned, i / 30).state for i in range(1, 6)]


def test_with_the_pixel_likeness_counted_a_turned_subject_is_doubted():
    assert TrackState.SEARCHING in _weighted_states(1.0)


def test_with_weight_zero_the_backends_score_alone_decides():
    assert _weighted_states(0.0) == [TrackState.TRACKING] * 5


# Refinement (``refine_blend``, on for the OpenCV backends): a confident box that sits a little
# off the subject is moved part-way onto the best template match near it.
OFFSET = 3.0  # px right of the subject (its size 40: within refine_reach's 4 px)


def _x_errors(**settings: float) -> list[float]:
    """The estimate's horizontal error over a moving subject whose backend answers ``OFFSET`` px right of it."""
    seq = render_sequence(frames=25, target=40, speed=2.0, seed=2)
    subject, _ = scripted_tracker(lambda n, restarts: ((seq.boxes[n][0] + OFFSET, *seq.boxes[n][1:]), 0.9),
                                  **settings)
    subject.init(seq.frames[0], seq.boxes[0], 0.0)
    estimates = follow(subject, seq.frames[1:])
    assert all(e.state is TrackState.TRACKING for e in estimates)
    return [center(e.box)[0] - center(truth)[0] for e, truth in zip(estimates, seq.boxes[1:])]


def test_an_offset_box_is_moved_halfway_onto_the_subject() -> None:
    settled = _x_errors()[-10:]
    assert abs(np.mean(settled) - OFFSET / 2) < 0.6, settled  # refine_blend 0.5


def test_without_refinement_the_offset_stays() -> None:
    settled = _x_errors(refine_blend=0.0)[-10:]
    assert abs(np.mean(settled) - OFFSET) < 0.3, settled


# The verification (``verify_deep``, on for nanotrack3): a backend that scores its box 1 on a cover
# must also show that the box still holds the subject, by its anchor likeness or by the pixels.
class _AnchoredBackend(ScriptedBackend):
    """A scripted backend that also reports a fixed ``anchor_likeness()``."""

    def __init__(self, answer, anchor: float) -> None:
        super().__init__(answer)
        self.anchor = anchor

    def anchor_likeness(self) -> float:
        return self.anchor


def _states_on_a_cover(anchor: float, **settings: float) -> list[TrackState]:
    """States while the backend answers the subject's last box with score 1 on a scene without it."""
    seq = render_sequence(frames=2, seed=3)
    backend = _AnchoredBackend(lambda n, restarts: (tuple(float(v) for v in seq.boxes[0]), 1.0), anchor)
    subject = SubjectTracker("anchored", backend, None, TrackerSettings(pixel_weight=0.0, **settings))
    subject.init(seq.frames[0], seq.boxes[0], 0.0)
    return [e.state for e in follow(subject, [empty_scene(3)] * 20)]


def test_an_unverified_box_is_a_miss_however_high_the_backend_scores_it():
    assert _states_on_a_cover(0.7, verify_deep=0.85)[-1] is TrackState.LOST
    assert _states_on_a_cover(0.9, verify_deep=0.85) == [TrackState.TRACKING] * 20  # the deep check holds it
    assert _states_on_a_cover(0.7) == [TrackState.TRACKING] * 20  # verification off: the score decides


def test_the_pixels_verify_a_box_the_deep_check_doubts():
    seq = render_sequence(frames=10, seed=3)
    backend = _AnchoredBackend(lambda n, restarts: (tuple(float(v) for v in seq.boxes[n]), 1.0), 0.5)
    subject = SubjectTracker("anchored", backend, None, TrackerSettings(pixel_weight=0.0, verify_deep=0.85))
    subject.init(seq.frames[0], seq.boxes[0], 0.0)
    assert [e.state for e in follow(subject, seq.frames[1:])] == [TrackState.TRACKING] * 9


class _VouchedBackend(_AnchoredBackend):
    """An anchored backend whose second model gives a fixed ``second_opinion()``."""

    def __init__(self, answer, anchor: float, opinion: float) -> None:
        super().__init__(answer, anchor)
        self.opinion = opinion

    def second_opinion(self) -> float:
        return self.opinion


def _states_vouched(opinion: float, answer: Box | None = None, **settings: float) -> list[TrackState]:
    """States on the rendered subject's scene without it while the backend answers ``answer`` (default:
    the subject's first box) with score 1, its deep check doubting (0.5) and a second model giving
    ``opinion``."""
    seq = render_sequence(frames=2, seed=3)
    answer = answer or tuple(float(v) for v in seq.boxes[0])
    backend = _VouchedBackend(lambda n, restarts: (answer, 1.0), 0.5, opinion)
    subject = SubjectTracker("vouched", backend, None, TrackerSettings(pixel_weight=0.0, verify_deep=0.85, **settings))
    subject.init(seq.frames[0], seq.boxes[0], 0.0)
    return [e.state for e in follow(subject, [empty_scene(3)] * 20)]


def test_a_second_models_confidence_vouches_for_a_box_the_deep_check_doubts():
    assert _states_vouched(0.6, verify_second=0.4) == [TrackState.TRACKING] * 20
    assert _states_vouched(0.3, verify_second=0.4)[-1] is TrackState.LOST  # under the bar: no vouching
    assert _states_vouched(0.6)[-1] is TrackState.LOST  # verify_second off: the second model is not asked


def test_the_second_model_does_not_vouch_for_a_box_at_the_frames_edge():
    """Its confidence there is in the part still in view of a subject leaving the picture."""
    assert _states_vouched(0.6, (100.0, 100.0, 40.0, 40.0), verify_second=0.4) == [TrackState.TRACKING] * 20
    assert _states_vouched(0.6, (285.0, 100.0, 40.0, 40.0), verify_second=0.4)[-1] is TrackState.LOST


@pytest.mark.parametrize("settings, needed", [({"verify_deep": 0.85}, "anchor_likeness"),
                                              ({"verify_deep": 0.85, "verify_second": 0.4}, "second_opinion")])
def test_a_check_the_backend_cannot_make_is_refused_not_skipped(settings, needed):
    """A wrapped backend without the check must not pass every box (``ConvertingBackend`` used to
    answer 1 for a missing ``anchor_likeness``)."""
    from tracker.backends import ConvertingBackend
    wrapped = ConvertingBackend(_AnchoredBackend(lambda n, restarts: (None, 0.0), 0.5) if needed == "second_opinion"
                                else ScriptedBackend(lambda n, restarts: (None, 0.0)), lambda frame: frame)
    with pytest.raises(ValueError, match=needed):
        SubjectTracker("wrapped", wrapped, None, TrackerSettings(**settings))


def test_a_wrapped_backend_passes_its_checks_through():
    from tracker.backends import ConvertingBackend
    wrapped = ConvertingBackend(_VouchedBackend(lambda n, restarts: (None, 0.0), 0.7, 0.6), lambda frame: frame)
    assert (wrapped.anchor_likeness(), wrapped.second_opinion()) == (0.7, 0.6)


def _box_while_doubted(pull: float) -> tuple[list[TargetEstimate], list[Box]]:
    """Estimates while an anchored backend follows the moving subject with score 1, its deep check
    doubting every box after the start and the pixels (a blank scene) not vouching either."""
    seq = render_sequence(frames=30, speed=3.0, seed=3)
    backend = _AnchoredBackend(lambda n, restarts: (tuple(float(v) for v in seq.boxes[n]), 1.0), 0.5)
    subject = SubjectTracker("anchored", backend, None,
                             TrackerSettings(pixel_weight=0.0, verify_deep=0.85, unverified_pull=pull))
    subject.init(seq.frames[0], seq.boxes[0], 0.0)
    return follow(subject, [np.full_like(seq.frames[0], 128)] * 29), seq.boxes[1:]


def test_while_searching_the_box_follows_an_unverified_box_when_told_to():
    followed, truth = _box_while_doubted(1.0)
    held, _ = _box_while_doubted(0.0)
    searching = [i for i, e in enumerate(followed) if e.state is TrackState.SEARCHING]
    assert len(searching) >= 10 and [e.state for e in held] == [e.state for e in followed]  # same states
    late = searching[5:]
    assert all(iou(followed[i].box, truth[i]) > 0.7 for i in late)
    assert all(iou(held[i].box, truth[i]) < 0.5 for i in late)
    lost = [e for e in followed if e.state is TrackState.LOST]
    assert lost and np.ptp([e.box[:2] for e in lost], axis=0) == pytest.approx((0.0, 0.0), abs=0.5)
