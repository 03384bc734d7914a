"""Every detector and tracking backend takes grey (H x W or H x W x 1), BGR and BGRA uint8 frames."""
import cv2
import numpy as np
import pytest

from tests import fake_onnx
from tracker.backends import BACKEND_NAMES, make_backend
from tracker.detectors import DETECTOR_KINDS, Detection, make_detector
from tracker.registry import make_tracker
from tracker.synthetic import render_sequence

FORMATS = ("grey", "grey x 1", "bgr", "bgra")
MODEL_BACKENDS = ("nanotrack", "nano")


def _as(frame: np.ndarray, fmt: str) -> np.ndarray:
    """A rendered BGR frame in ``fmt``."""
    grey = cv2.cvtColor(frame, cv2.COLOR_BGR2GRAY)
    return {"grey": grey, "grey x 1": grey[:, :, None], "bgr": frame,
            "bgra": cv2.cvtColor(frame, cv2.COLOR_BGR2BGRA)}[fmt]


@pytest.fixture(scope="module")
def fake_models(tmp_path_factory):
    """NanoTrack-shaped networks (tests/fake_onnx.py): the backends run without the shared model files."""
    folder = tmp_path_factory.mktemp("models")
    return fake_onnx.write_nanotrack_files(folder, fake_onnx.backbone_bytes(), fake_onnx.head_bytes())


def _detector(kind: str, request: pytest.FixtureRequest):
    """``face`` is Haar without a model folder; ``face-yunet`` needs the shared models (skipped without)."""
    if kind == "face-yunet":
        return make_detector("face", request.getfixturevalue("shared_data") / "models")
    return make_detector(kind)


DETECTORS = (*DETECTOR_KINDS, "face-yunet")


@pytest.mark.parametrize("fmt", FORMATS)
@pytest.mark.parametrize("kind", DETECTORS)
def test_every_detector_takes_every_frame_format(kind, fmt, request):
    detector = _detector(kind, request)
    frames = [_as(f, fmt) for f in render_sequence(frames=4, speed=6.0, seed=8).frames]
    found = [detector.detect(f) for f in frames]
    assert all(isinstance(d, Detection) and 0.0 <= d.score <= 1.0 for frame in found for d in frame)
    if kind == "motion":
        assert found[-1], "the moving target is found in every format"


def test_motion_finds_the_same_boxes_in_every_format():
    frames = render_sequence(frames=6, speed=6.0, seed=8).frames
    boxes = {fmt: [[d.box for d in make_detector("motion").detect(_as(f, fmt))] for f in frames] for fmt in FORMATS}
    assert all(found == boxes["bgr"] for found in boxes.values())


@pytest.mark.parametrize("kind", DETECTORS)
def test_an_empty_frame_gives_no_detections(kind, request):
    detector = _detector(kind, request)
    frame = render_sequence(frames=1, seed=8).frames[0]
    assert detector.detect(np.zeros((0, 0, 3), np.uint8)) == []
    assert isinstance(detector.detect(frame), list)  # and it still works afterwards


@pytest.mark.parametrize("fmt", FORMATS)
@pytest.mark.parametrize("name", BACKEND_NAMES)
def test_every_backend_takes_every_frame_format(name, fmt, fake_models):
    seq = render_sequence(frames=4, speed=3.0, seed=3)
    backend = make_backend(name, fake_models if name in MODEL_BACKENDS else None)
    backend.init(_as(seq.frames[0], fmt), seq.boxes[0])
    for frame in seq.frames[1:]:
        box, score = backend.update(_as(frame, fmt))
        assert 0.0 <= score <= 1.0 and (box is None or len(box) == 4)


@pytest.mark.parametrize("fmt", FORMATS)
@pytest.mark.parametrize("name", BACKEND_NAMES)
def test_every_tracker_follows_every_frame_format(name, fmt, fake_models):
    """Through ``make_tracker``, as ``gimbaltrack track`` uses them (KCF and OpenCV's Nano once raised on
    grey frames, every tracker on BGRA)."""
    seq = render_sequence(frames=4, speed=3.0, seed=3)
    subject = make_tracker(name, fake_models if name in MODEL_BACKENDS else None)
    subject.init(_as(seq.frames[0], fmt), seq.boxes[0], 0.0)
    estimates = [subject.update(_as(f, fmt), i / 30.0) for i, f in enumerate(seq.frames[1:], 1)]
    assert all(np.isfinite(e.box).all() for e in estimates)
