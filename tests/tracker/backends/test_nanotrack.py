"""Our NanoTrack backend: the numpy post-processing on hand-made maps, and tracking with the models."""
from __future__ import annotations

from collections import Counter
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import pytest

from tests import fake_onnx
from tests.tracker.backends.occlusion_clip import lookalike_occlusion
from tracker.backends import make_backend
from tracker.backends.nanotrack import (
    NanoTrackBackend, NanoTrackParams, SCORE_SIZE, change_penalty, cosine_likeness, crop_square, decode_boxes,
    foreground_score, grid_offsets, hanning_window, load_nanotrack_networks, sample_cells, select_peak,
)
from tracker.evaluation.metrics import success_auc
from tracker.evaluation.synthetic import render_sequence
from tracker.runtime.boxes import iou
from tracker.runtime.estimate import TrackState
from tracker.runtime.subject import SubjectTracker


def test_hanning_window_peaks_in_the_middle_and_vanishes_on_the_border():
    window = hanning_window(16)
    assert window.shape == (16, 16)
    assert np.allclose(window, window.T)
    assert window[0].max() == pytest.approx(0.0) and window[:, -1].max() == pytest.approx(0.0)
    assert np.unravel_index(window.argmax(), window.shape) in {(7, 7), (7, 8), (8, 7), (8, 8)}


def test_grid_offsets_step_by_the_stride_around_the_crop_centre():
    offsets = grid_offsets(16, 16)
    assert offsets[0] == -128 and offsets[8] == 0 and offsets[-1] == 112
    assert np.all(np.diff(offsets) == 16)


def test_foreground_score_is_a_softmax_over_the_two_channels():
    cls = np.zeros((2, 3, 3), np.float32)
    cls[1, 0, 0] = 50.0  # sure foreground, large logits must not overflow
    cls[0, 2, 2] = np.log(3.0)  # background three times as likely
    score = foreground_score(cls)
    assert score[0, 0] == pytest.approx(1.0)
    assert score[1, 1] == pytest.approx(0.5)
    assert score[2, 2] == pytest.approx(0.25)


def test_decode_boxes_turns_side_distances_into_centred_boxes():
    offsets = grid_offsets(4, 16)  # -32, -16, 0, 16
    loc = np.zeros((4, 4, 4), np.float32)
    loc[:, :, :] = np.array([10.0, 5.0, 30.0, 15.0])[:, None, None]  # left, top, right, bottom
    boxes = decode_boxes(loc, offsets)
    assert boxes.shape == (4, 4, 4)
    cx, cy, w, h = boxes[:, 1, 2]  # row 1 (y = -16), column 2 (x = 0)
    assert (cx, cy, w, h) == pytest.approx((10.0, -11.0, 40.0, 20.0))


def test_change_penalty_is_one_without_change_and_symmetric_in_scale():
    k = 0.15
    w = np.array([40.0, 80.0, 20.0, 40.0])
    h = np.array([20.0, 40.0, 10.0, 40.0])
    penalty = change_penalty(w, h, 40.0, 20.0, k)
    assert penalty[0] == pytest.approx(1.0)
    assert penalty[1] == pytest.approx(np.exp(-k))  # twice as big, same aspect ratio
    assert penalty[2] == pytest.approx(penalty[1])  # half as big
    assert penalty[3] < penalty[0]  # same area-ish, other aspect ratio


def test_select_peak_trades_score_against_distance_from_the_centre():
    boxes = decode_boxes(np.full((4, SCORE_SIZE, SCORE_SIZE), 20.0, np.float32), grid_offsets())
    score = np.zeros((SCORE_SIZE, SCORE_SIZE), np.float32)
    score[8, 8] = 0.6  # near the centre
    score[1, 14] = 0.95  # near the border
    window, target = hanning_window(SCORE_SIZE), np.array([40.0, 40.0])
    (row, col), penalty = select_peak(score, boxes, target, window, NanoTrackParams())
    assert (row, col) == (8, 8) and penalty == pytest.approx(1.0)
    (row, col), _ = select_peak(score, boxes, target, window, NanoTrackParams(window_influence=0.0))
    assert (row, col) == (1, 14)


def test_select_peak_prefers_the_box_that_keeps_the_size():
    loc = np.full((4, SCORE_SIZE, SCORE_SIZE), 20.0, np.float32)
    loc[:, 8, 9] = 60.0  # a box three times as big, next to the centre
    boxes = decode_boxes(loc, grid_offsets())
    score = np.zeros((SCORE_SIZE, SCORE_SIZE), np.float32)
    score[8, 8] = score[8, 9] = 0.9
    (row, col), _ = select_peak(score, boxes, np.array([40.0, 40.0]), np.ones_like(score),
                                NanoTrackParams(window_influence=0.0))
    assert (row, col) == (8, 8)


def test_crop_square_cuts_the_region_and_fills_outside_the_frame():
    frame = np.arange(20 * 30 * 3, dtype=np.uint8).reshape(20, 30, 3)
    crop = crop_square(frame, 15.0, 10.0, 10.0, 10, (1.0, 2.0, 3.0))
    assert np.array_equal(crop, frame[5:15, 10:20])
    corner = crop_square(frame, 0.0, 0.0, 10.0, 10, (1.0, 2.0, 3.0))
    assert np.array_equal(corner[0, 0], [1, 2, 3])
    assert np.array_equal(corner[5:, 5:], frame[:5, :5])


def test_missing_model_files_raise_file_not_found(tmp_path):
    with pytest.raises(FileNotFoundError, match="nanotrack_backbone"):
        NanoTrackBackend(tmp_path)
    with pytest.raises(FileNotFoundError):
        NanoTrackBackend(None)


def test_networks_shaped_like_nanotracks_pass_the_load_check(tmp_path):
    models = fake_onnx.write_nanotrack_files(tmp_path, fake_onnx.backbone_bytes(), fake_onnx.head_bytes())
    backbone, head = load_nanotrack_networks(models)
    assert not backbone.empty() and not head.empty()
    backend = NanoTrackBackend(models)
    frame = render_sequence(frames=1, seed=1).frames[0]
    backend.init(frame, (100.0, 80.0, 40.0, 40.0))
    box, score = backend.update(frame)
    assert box is not None and 0.0 <= score <= 1.0


@pytest.mark.parametrize("backbone, head, wrong", [
    (b"junk!", fake_onnx.head_bytes(), r"backbone .*nanotrack_backbone_sim.onnx: not a readable ONNX network"),
    (fake_onnx.backbone_bytes(), b"", r"neck/head .*nanotrack_head_sim.onnx: not a readable ONNX network"),
    (fake_onnx.head_bytes(), fake_onnx.backbone_bytes(), r"nanotrack_backbone_sim.onnx: not NanoTrack's backbone"),
    (fake_onnx.backbone_bytes(), fake_onnx.backbone_bytes(), r"nanotrack_head_sim.onnx: not NanoTrack's neck/head"),
])
@pytest.mark.parametrize("name", ["nanotrack", "nano"])
def test_wrong_or_damaged_model_files_are_named_when_the_backend_is_made(tmp_path, backbone, head, wrong, name):
    """Once a cv2.error: on loading (junk), on the first search (swapped) or in init() (``nano``)."""
    models = fake_onnx.write_nanotrack_files(tmp_path, backbone, head)
    with pytest.raises(ValueError, match=wrong):
        make_backend(name, models)


def test_update_before_init_is_an_error(shared_data):
    backend = NanoTrackBackend(shared_data / "models")
    with pytest.raises(RuntimeError, match="before init"):
        backend.update(np.zeros((240, 320, 3), np.uint8))


def test_follows_a_moving_target(shared_data):
    seq = render_sequence(frames=50, speed=4.0, scale_change=1.3, seed=7)
    backend = NanoTrackBackend(shared_data / "models")
    backend.init(seq.frames[0], seq.boxes[0])
    results = [backend.update(frame) for frame in seq.frames[1:]]
    boxes = [seq.boxes[0]] + [box for box, _ in results]
    assert success_auc(boxes, seq.boxes) > 0.7
    assert iou(boxes[-1], seq.boxes[-1]) > 0.5
    assert all(0.0 <= score <= 1.0 for _, score in results)


def test_grey_frames_are_tracked_too(shared_data):
    seq = render_sequence(frames=20, seed=8)
    grey = [cv2.cvtColor(frame, cv2.COLOR_BGR2GRAY) for frame in seq.frames]
    backend = NanoTrackBackend(shared_data / "models")
    backend.init(grey[0], seq.boxes[0])
    box, _ = [backend.update(frame) for frame in grey[1:]][-1]
    assert iou(box, seq.boxes[-1]) > 0.5


def test_follows_a_moving_target_inside_the_subject_tracker(shared_data):
    seq = render_sequence(frames=50, seed=7)
    subject = SubjectTracker("nanotrack", NanoTrackBackend(shared_data / "models"))
    estimates = [subject.init(seq.frames[0], seq.boxes[0], 0.0)]
    estimates += [subject.update(frame, i / 30.0) for i, frame in enumerate(seq.frames[1:], 1)]
    assert success_auc([e.box for e in estimates], seq.boxes) > 0.7


def _size_error_on_the_first_frame(shared_data, strength: float) -> float:
    """How far the box found on the frame the backend was given on strays from the given size."""
    seq = render_sequence(frames=2, seed=7)
    x, y, w, h = seq.boxes[0]
    given = (x + 0.1 * w, y + 0.1 * h, 0.8 * w, 0.8 * h)  # a tight box: the network's sides disagree
    backend = NanoTrackBackend(shared_data / "models", NanoTrackParams(calibration_strength=strength))
    backend.init(seq.frames[0], given)
    box, _ = backend.update(seq.frames[0])
    return float(np.max(np.abs(np.log(np.array(box[2:]) / np.array(given[2:])))))


def test_size_calibration_keeps_the_given_box_convention(shared_data):
    assert _size_error_on_the_first_frame(shared_data, 0.0) > 0.03  # uncalibrated: the box drifts
    assert _size_error_on_the_first_frame(shared_data, 1.0) < 0.02  # fully calibrated: it stays


def test_size_calibration_is_clipped_and_off_at_zero_strength(shared_data):
    seq = render_sequence(frames=2, seed=7)
    params = NanoTrackParams(calibration_strength=8.0, calibration_limits=(0.95, 1.05))
    backend = NanoTrackBackend(shared_data / "models", params)
    backend.init(seq.frames[0], seq.boxes[0])
    assert np.all((backend.size_calibration >= 0.95) & (backend.size_calibration <= 1.05))
    assert np.any(backend.size_calibration != 1.0)
    off = NanoTrackBackend(shared_data / "models", NanoTrackParams(calibration_strength=0.0))
    off.init(seq.frames[0], seq.boxes[0])
    assert np.array_equal(off.size_calibration, np.ones(2))


def test_sample_cells_interpolates_between_cells_and_clamps_at_the_border():
    features = np.arange(2 * 4 * 4, dtype=np.float32).reshape(2, 4, 4)
    assert np.array_equal(sample_cells(features, (1.5, 1.5), (2, 2)), features[:, 1:3, 1:3])
    assert np.allclose(sample_cells(features, (1.0, 2.0), (1, 1))[:, 0, 0], features[:, 2, 1])
    assert np.allclose(sample_cells(features, (1.25, 2.0), (1, 1))[:, 0, 0], features[:, 2, 1] + 0.25)
    assert np.array_equal(sample_cells(features, (-3.0, 9.0), (1, 1))[:, 0, 0], features[:, 3, 0])


def test_cosine_likeness_is_one_for_the_same_look_and_zero_for_opposite_or_empty_ones():
    block = np.random.default_rng(0).normal(size=(3, 2, 2))
    assert cosine_likeness(block, 2.0 * block) == pytest.approx(1.0)
    assert cosine_likeness(block, -block) == 0.0
    assert cosine_likeness(block, np.zeros_like(block)) == 0.0


FEAR_COLLAPSES = pytest.mark.xfail(strict=True, reason=(
    "known failure: FEAR-XS's box (taken as the network gives it, as its reference does) shrinks to 8 px "
    "wide on this clip before the face hides, and stays on the cover with the subject tracker's pixel "
    "likeness (0.34) over its gate; a per-frame template-feature likeness did not separate them"))


@pytest.mark.parametrize("name", ["nanotrack", "nanotrack3", "nanovit", "vittrack", pytest.param("fear", marks=FEAR_COLLAPSES)])
def test_a_hidden_subject_is_not_reported_on_a_lookalike(shared_data, name):
    """NanoTrack's foreground score stays near 1 on background; the deep-feature likeness makes the
    subject tracker say ``searching`` and then ``lost`` instead of ``tracking`` on a look-alike. Every
    model backend's score must do the same."""
    images, boxes, hidden = lookalike_occlusion(shared_data)
    subject = SubjectTracker(name, make_backend(name, shared_data / "models"))
    subject.init(images[0], boxes[0], 0.0)
    estimates = [subject.update(image, i / 30.0) for i, image in enumerate(images[1:], 1)]
    hidden_estimates = [e for e, h in zip(estimates, hidden[1:]) if h]
    assert len(hidden_estimates) >= 25
    assert not any(e.state is TrackState.TRACKING for e in hidden_estimates)
    assert hidden_estimates[-1].state is TrackState.LOST
    assert all(e.state is not TrackState.TRACKING or iou(e.box, box) > 0.3 for e, box in zip(estimates, boxes[1:]))


def test_the_score_falls_where_the_subject_is_gone_though_the_foreground_score_stays_high(tmp_path):
    """With a head sure of the foreground everywhere, only the likeness of the backbone's features
    (here: mean colours of 16 px blocks) under the chosen box to the subject's tells them apart. Its
    flat scores tie, and the cosine window's first maximum moves the box 16 px up and left a frame
    (without velocity), so the frames are one colour each."""
    models = fake_onnx.write_nanotrack_files(tmp_path, fake_onnx.backbone_bytes(), fake_onnx.head_bytes(sure=True))
    subject = np.full((480, 640, 3), (20, 40, 220), np.uint8)
    ground = np.full((480, 640, 3), (200, 60, 20), np.uint8)
    backend = NanoTrackBackend(models, NanoTrackParams(velocity_gain=0.0))
    backend.init(subject, (288.0, 208.0, 64.0, 64.0))
    assert min(backend.update(subject)[1] for _ in range(3)) > 0.9
    assert max(backend.update(ground)[1] for _ in range(3)) < 0.5
    assert min(backend.update(subject)[1] for _ in range(3)) > 0.9  # the typical likeness did not sink


def test_a_box_about_half_as_like_the_subject_as_usual_falls_under_the_gate(tmp_path):
    """The likeness factor ramps from 0 at half the typical deep likeness (``likeness_zero``) to 1 at
    ``likeness_full`` of it: a background box at ~0.52 of it (where NanoTrack's boxes on background
    sat just over the 0.25 gate while the subject was hidden) scores under the gate, with a head
    sure of the foreground; the subject itself keeps a full score."""
    models = fake_onnx.write_nanotrack_files(tmp_path, fake_onnx.backbone_bytes(), fake_onnx.head_bytes(sure=True))
    look, half = np.array([20.0, 40.0, 220.0]), np.array([150.0, 100.0, 70.0])
    assert 0.5 < cosine_likeness(look, half) < 0.55  # the fake backbone's features are mean colours
    subject = np.full((480, 640, 3), look, np.uint8)
    ground = np.full((480, 640, 3), half, np.uint8)
    backend = NanoTrackBackend(models, NanoTrackParams(velocity_gain=0.0))
    backend.init(subject, (288.0, 208.0, 64.0, 64.0))
    assert min(backend.update(subject)[1] for _ in range(3)) > 0.9
    assert max(backend.update(ground)[1] for _ in range(3)) < 0.25


def test_likeness_scores_a_box_against_the_subject_relative_to_its_typical_likeness(tmp_path):
    """``likeness`` (used before a restart): ~1 for a box on the subject, its cosine with the
    subject's look for a box on another colour; 1 before the typical likeness is known."""
    models = fake_onnx.write_nanotrack_files(tmp_path, fake_onnx.backbone_bytes(), fake_onnx.head_bytes(sure=True))
    look, other = np.array([20.0, 40.0, 220.0]), np.array([200.0, 60.0, 20.0])
    subject = np.full((480, 640, 3), look, np.uint8)
    ground = np.full((480, 640, 3), other, np.uint8)
    backend = NanoTrackBackend(models, NanoTrackParams(velocity_gain=0.0))
    box = (288.0, 208.0, 64.0, 64.0)
    backend.init(subject, box)
    assert backend.likeness(ground, box) == 1.0
    backend.update(subject)
    assert backend.likeness(subject, (100.0, 50.0, 80.0, 60.0)) == pytest.approx(1.0, abs=0.02)
    assert backend.likeness(ground, box) == pytest.approx(cosine_likeness(look, other), abs=0.02)


# ``nano`` (OpenCV's TrackerNano, which takes model paths only) reads each model file once per
# backend: not once to check the files and again for the tracker, nor again on every restart.
def test_each_model_file_is_loaded_once_however_often_the_backend_restarts(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    models = fake_onnx.write_nanotrack_files(tmp_path, fake_onnx.backbone_bytes(), fake_onnx.head_bytes())
    loads: Counter[str] = Counter()
    read_net, create = cv2.dnn.readNet, cv2.TrackerNano_create

    def counted_read(path: str, *args: Any) -> cv2.dnn.Net:
        loads[Path(path).name] += 1
        return read_net(path, *args)

    def counted_create(params: cv2.TrackerNano_Params) -> cv2.TrackerNano:
        loads.update([Path(params.backbone).name, Path(params.neckhead).name])
        return create(params)

    monkeypatch.setattr(cv2.dnn, "readNet", counted_read)
    monkeypatch.setattr(cv2, "TrackerNano_create", counted_create)
    backend = make_backend("nano", models)
    frame = render_sequence(frames=1, seed=1).frames[0]
    for _ in range(3):  # the start and two restarts (re-acquisitions)
        backend.init(frame, (100.0, 80.0, 40.0, 40.0))
        backend.update(frame)
    assert loads == {"nanotrack_backbone_sim.onnx": 1, "nanotrack_head_sim.onnx": 1}


def test_a_restart_tracks_as_a_fresh_backend_does(shared_data: Path) -> None:
    """The one TrackerNano is initialised again on a restart: nothing of the earlier run stays."""
    seq = render_sequence(frames=12, speed=4.0, seed=7)
    used = make_backend("nano", shared_data / "models")
    used.init(seq.frames[0], seq.boxes[0])
    for frame in seq.frames[1:6]:
        used.update(frame)
    fresh = make_backend("nano", shared_data / "models")
    for backend in (used, fresh):
        backend.init(seq.frames[6], seq.boxes[6])
    assert [used.update(f) for f in seq.frames[7:]] == [fresh.update(f) for f in seq.frames[7:]]


def test_files_that_pass_the_check_but_not_trackernano_are_a_value_error(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """E.g. an OpenCV whose TrackerNano cannot run them: said when the backend is made, not mid-run."""
    models = fake_onnx.write_nanotrack_files(tmp_path, fake_onnx.backbone_bytes(), fake_onnx.head_bytes())

    def refuse(params: cv2.TrackerNano_Params) -> cv2.TrackerNano:
        raise cv2.error("OpenCV(4.x) tracker_nano.cpp:1: error: (-215:Assertion failed) something")

    monkeypatch.setattr(cv2, "TrackerNano_create", refuse)
    with pytest.raises(ValueError, match=r"^OpenCV's TrackerNano cannot use .*nanotrack_backbone_sim.onnx "
                                         r"and .*nanotrack_head_sim.onnx: .*Assertion failed\) something$"):
        make_backend("nano", models)


def test_nanotrack3s_anchor_likeness_falls_on_a_cover_where_its_score_does_not():
    """On the rendered occlusion clip the network's box stays on the cover with a score near 1; the
    likeness to the subject as first seen, over its early value held, is what tells them apart."""
    from tracker.evaluation.synthetic import render_sequence
    from tracker.runtime.registry import EMBEDDED_MODELS

    seq = render_sequence(frames=46, occlusion=(25, 45), seed=1)
    backend = make_backend("nanotrack3", EMBEDDED_MODELS)
    backend.init(seq.frames[0], seq.boxes[0])
    answers = [(backend.update(frame)[1], backend.anchor_likeness()) for frame in seq.frames[1:]]
    assert min(anchor for _, anchor in answers[:10]) > 0.9  # the subject in view
    hidden = answers[34:45]  # frames 35-45: the subject behind the cover
    assert min(score for score, _ in hidden) > 0.9 and max(anchor for _, anchor in hidden) < 0.85
