"""VitTrack, FEAR-XS and NanoTrack v3 on onnxruntime, with tiny networks made by the tests: each
network's score map follows a white square on black, so where the square goes the box must go, and
where it is gone the score must fall and the subject tracker must report the subject lost."""
import numpy as np
import pytest

from tests import fake_onnx
from tracker.backends import make_backend
from tracker.runtime.boxes import center
from tracker.runtime.estimate import TrackState
from tracker.backends.fear import FearBackend, decode_best, grid_points
from tracker.backends.onnx_sessions import OnnxNetwork
from tracker.runtime.registry import make_tracker
from tracker.runtime.subject import SubjectTracker
from tracker.backends.vittrack import VitTrackBackend, centred_hann, decode_peak, normalised_blob

MODELS = ("vittrack", "fear", "nanotrack3")
SIDE = 32


@pytest.fixture(scope="module")
def models(tmp_path_factory):
    return fake_onnx.onnx_model_files(tmp_path_factory.mktemp("models"))


def _frame(x: float, y: float, side: int = SIDE, shape=(360, 480)) -> np.ndarray:
    """Black, with the subject at (x, y) unless x < 0: a bright square, its left half a little darker
    (a uniform patch would leave the subject tracker's pixel likeness undefined)."""
    frame = np.zeros((*shape, 3), np.uint8)
    if x >= 0:
        frame[int(y):int(y) + side, int(x):int(x) + side] = 255
        frame[int(y):int(y) + side, int(x):int(x) + side // 2] = 190
    return frame


@pytest.mark.parametrize("name", MODELS)
def test_the_box_moves_to_where_the_score_map_peaks(models, name):
    backend = make_backend(name, models)
    backend.init(_frame(200, 150), (200.0, 150.0, SIDE, SIDE))
    box, score = backend.update(_frame(212, 142))  # moved by 12 px right and 8 px up
    assert score > 0.5
    cx, cy = center(box)
    assert abs(cx - (212 + SIDE / 2)) <= 5 and abs(cy - (142 + SIDE / 2)) <= 5


@pytest.mark.parametrize("name", MODELS)
def test_the_score_follows_the_map_and_falls_where_the_subject_is_gone(models, name):
    backend = make_backend(name, models)
    backend.init(_frame(200, 150), (200.0, 150.0, SIDE, SIDE))
    seen = [backend.update(_frame(200, 150))[1] for _ in range(3)]
    gone = [backend.update(_frame(-1, -1))[1] for _ in range(3)]
    assert min(seen) > 0.6
    assert max(gone) < 0.2


@pytest.mark.parametrize("name", MODELS)
def test_a_subject_that_leaves_is_reported_searching_then_lost(models, name):
    subject = SubjectTracker(name, make_backend(name, models))
    subject.init(_frame(200, 150), (200.0, 150.0, SIDE, SIDE), 0.0)
    present = [subject.update(_frame(200, 150), i / 30) for i in range(1, 10)]
    absent = [subject.update(_frame(-1, -1), i / 30) for i in range(10, 40)]
    assert all(e.state is TrackState.TRACKING for e in present)
    assert absent[0].state is TrackState.SEARCHING
    assert TrackState.TRACKING not in {e.state for e in absent}
    assert absent[-1].state is TrackState.LOST


def test_vittrack_normalises_each_channel_with_its_own_mean_and_std():
    crop = np.zeros((2, 2, 3), np.uint8)
    crop[..., 0], crop[..., 1], crop[..., 2] = 255, 0, 128  # B, G, R
    blob = normalised_blob(crop)
    assert blob.shape == (1, 3, 2, 2)
    np.testing.assert_allclose(blob[0, :, 0, 0], [(1 - 0.485) / 0.229, (0 - 0.456) / 0.224,
                                                  (128 / 255 - 0.406) / 0.225], rtol=1e-5)


def test_vittrack_decodes_the_windowed_peak_into_crop_fractions():
    conf = np.zeros((16, 16), np.float32)
    conf[4, 10] = 0.9
    conf[8, 8] = 0.3
    size = np.zeros((2, 16, 16), np.float32)
    size[:, 4, 10] = (0.2, 0.3)
    offset = np.full((2, 16, 16), 0.25, np.float32)
    (cx, cy, w, h), score = decode_peak(conf, size, offset, centred_hann(16))
    assert (cx, cy, w, h) == pytest.approx(((10 + 0.25) / 16, (4 + 0.25) / 16, 0.2, 0.3))
    assert score == pytest.approx(0.9 * centred_hann(16)[4, 10])


def test_vittrack_holds_its_box_where_the_confidence_is_under_the_reference_threshold(models):
    backend = VitTrackBackend(models)
    backend.init(_frame(200, 150), (200.0, 150.0, SIDE, SIDE))
    assert backend.update(_frame(-1, -1))[0] is None
    box, _ = backend.update(_frame(200, 150))  # found where it was held
    assert abs(center(box)[0] - 216) <= 8


def test_fear_grid_and_decoding_follow_the_reference():
    assert grid_points()[[0, 8, 15]].tolist() == [0.0, 128.0, 240.0]
    cls = np.full((16, 16), -5.0, np.float32)
    cls[3, 12] = 4.0
    bbox = np.stack([np.full((16, 16), v, np.float32) for v in (10, 20, 30, 40)])
    (x1, y1, x2, y2), score = decode_best(cls, bbox, None, 0.0)
    assert (x1, y1, x2, y2) == (192 - 10, 48 - 20, 192 + 30, 48 + 40)
    assert score == pytest.approx(1 / (1 + np.exp(-4.0)))


def test_fear_likeness_is_relative_to_the_subjects_typical_likeness(models):
    backend = FearBackend(models)
    backend.init(_frame(200, 150), (200.0, 150.0, SIDE, SIDE))
    assert backend.likeness(_frame(200, 150), (200.0, 150.0, SIDE, SIDE)) == 1.0  # nothing typical known yet
    backend.update(_frame(200, 150))
    assert backend.likeness(_frame(200, 150), (200.0, 150.0, SIDE, SIDE)) == pytest.approx(1.0, abs=0.05)
    assert backend.likeness(_frame(200, 150), (100.0, 50.0, SIDE, SIDE)) < 0.1


def test_vittrack_likeness_is_high_on_the_subject_and_low_elsewhere(models):
    backend = VitTrackBackend(models)
    backend.init(_frame(200, 150), (200.0, 150.0, SIDE, SIDE))
    backend.update(_frame(200, 150))
    assert backend.likeness(_frame(200, 150), (200.0, 150.0, SIDE, SIDE)) > 0.8
    assert backend.likeness(_frame(200, 150), (40.0, 40.0, SIDE, SIDE)) < 0.1


@pytest.mark.parametrize("name, broken, message", [
    ("vittrack", "vittrack/vitTracker.onnx", r"VitTrack network .*vitTracker.onnx: not a readable ONNX network"),
    ("fear", "fear_xs/fear_xs_search.onnx", r"FEAR-XS search network .*fear_xs_search.onnx: not a readable"),
    ("nanotrack3", "nanotrack_v3/nanotrack_head.onnx", r"NanoTrack v3 neck/head .*nanotrack_head.onnx: not a"),
])
def test_a_damaged_model_file_is_named(models, tmp_path, name, broken, message):
    copy = fake_onnx.onnx_model_files(tmp_path)
    (copy / broken).write_bytes(b"junk!")
    with pytest.raises(ValueError, match=message):
        make_backend(name, copy)


def test_another_network_in_a_models_place_is_named(tmp_path):
    fake_onnx.write_model_files(tmp_path, {"vittrack/vitTracker.onnx": fake_onnx.fear_template_bytes()})
    with pytest.raises(ValueError, match=r"vitTracker.onnx: not the expected network \(it must take template"):
        make_backend("vittrack", tmp_path)


@pytest.mark.parametrize("name", MODELS)
def test_missing_model_files_raise_file_not_found(tmp_path, name):
    with pytest.raises(FileNotFoundError):
        make_backend(name, tmp_path)


def test_sessions_run_on_the_threads_asked_for(models):
    inputs = {"image": (1, 3, 128, 128)}
    network = OnnxNetwork(models / "fear_xs/fear_xs_template.onnx", "t", inputs, {"features": (1, 256, 8, 8)}, threads=2)
    assert network._session.get_session_options().intra_op_num_threads == 2
    with pytest.raises(ValueError, match="threads must be at least 1"):
        OnnxNetwork(models / "fear_xs/fear_xs_template.onnx", "t", inputs, {"features": (1, 256, 8, 8)}, threads=0)


@pytest.mark.parametrize("name", MODELS)
def test_grey_and_bgra_frames_are_tracked_too(models, name):
    backend = make_backend(name, models)
    grey = _frame(200, 150)[..., 0]
    backend.init(grey, (200.0, 150.0, SIDE, SIDE))
    box, score = backend.update(np.dstack([_frame(208, 150), np.full((360, 480), 255, np.uint8)]))
    assert score > 0.5 and abs(center(box)[0] - 224) <= 5


@pytest.mark.parametrize("name", ["nanotrack3", "nanovit"])
def test_nanotrack3_made_by_name_reports_a_subject_that_leaves_lost(models, name):
    """As made by ``make_tracker`` (its confidence from the backend's score alone, under a lower gate;
    ``nanovit`` shares the settings and NanoTrack's score)."""
    subject = make_tracker(name, models)
    subject.init(_frame(200, 150), (200.0, 150.0, SIDE, SIDE), 0.0)
    present = [subject.update(_frame(200, 150), i / 30) for i in range(1, 10)]
    absent = [subject.update(_frame(-1, -1), i / 30) for i in range(10, 40)]
    assert all(e.state is TrackState.TRACKING for e in present)
    assert TrackState.TRACKING not in {e.state for e in absent}
    assert absent[-1].state is TrackState.LOST
