"""Detectors: motion on rendered frames; face and person construct and run."""
import subprocess
import sys

import numpy as np
import pytest

from tracker.boxes import iou
from tracker.detectors import Detection, HaarFaceDetector, make_detector
from tracker.synthetic import render_sequence, texture


def test_motion_finds_the_moving_target_once_it_has_three_frames():
    seq = render_sequence(frames=12, speed=6.0, seed=8)
    detector = make_detector("motion")
    results = [detector.detect(frame) for frame in seq.frames]
    assert results[0] == [] and results[1] == []
    for found, truth in zip(results[4:], seq.boxes[4:]):
        assert found and iou(found[0].box, truth) > 0.5


def test_motion_ignores_a_static_scene():
    frame = render_sequence(frames=1, seed=9).frames[0]
    detector = make_detector("motion")
    assert [detector.detect(frame.copy()) for _ in range(4)] == [[], [], [], []]


def test_motion_reports_the_largest_moving_thing_first():
    rng = np.random.default_rng(12)
    small, big = texture(12, 12, rng, cell=3, contrast=1.0), texture(50, 50, rng, cell=5, contrast=1.0)
    frames = [np.full((120, 160, 3), 128, np.uint8) for _ in range(3)]
    for i, frame in enumerate(frames):
        frame[10 + 14 * i:22 + 14 * i, 10:22] = small
        frame[40:90, 40 + 20 * i:90 + 20 * i] = big
    detector = make_detector("motion")
    found = [detector.detect(f) for f in frames][-1]
    assert len(found) >= 2 and found[0].box[2] * found[0].box[3] > found[1].box[2] * found[1].box[3]


@pytest.mark.parametrize("kind", ["face", "person"])
def test_builtin_detectors_need_no_model_files_and_run(kind):
    frame = render_sequence(frames=1, frame_size=(320, 240), seed=10).frames[0]
    found = make_detector(kind).detect(frame)
    assert isinstance(found, list)
    assert all(isinstance(d, Detection) and 0.0 <= d.score <= 1.0 for d in found)


def test_unknown_kind(tmp_path):
    with pytest.raises(ValueError, match="unknown detector kind 'cat'"):
        make_detector("cat")


def test_a_model_dir_without_yunet_falls_back_to_haar(tmp_path):
    """As documented: YuNet only when the folder holds its file (e.g. not a NanoTrack-only folder)."""
    (tmp_path / "nanotrack_v2").mkdir()
    (tmp_path / "nanotrack_v2" / "nanotrack_backbone_sim.onnx").write_bytes(b"")
    assert isinstance(make_detector("face", tmp_path), HaarFaceDetector)  # once a FileNotFoundError


def test_person_detector_gives_nothing_on_frames_smaller_than_its_window():
    """In a child process: on such frames OpenCV's HOG once corrupted memory and aborted the process
    (and a 0 x 0 frame divided by zero)."""
    code = ("import numpy as np; from tracker.detectors import make_detector; d = make_detector('person'); "
            "sizes = [(0, 0), (8, 8), (16, 16), (24, 24), (32, 32), (127, 64), (128, 63), (40, 2000)]; "
            "print([d.detect(np.zeros((h, w, 3), np.uint8)) for h, w in sizes]); "
            "print(isinstance(d.detect(np.zeros((128, 64, 3), np.uint8)), list))")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["[[],"] + ["[],"] * 6 + ["[]]", "True"]


def test_yunet_loads_from_the_shared_models(shared_data):
    detector = make_detector("face", shared_data / "models")
    frame = render_sequence(frames=1, seed=11).frames[0]
    assert all(0.0 <= d.score <= 1.0 for d in detector.detect(frame))


def test_hog_finds_people_in_the_pets_clip(shared_data):
    import cv2
    capture = cv2.VideoCapture(str(shared_data / "clips/clip_pets_768x576/768x576.avi"))
    ok, frame = capture.read()
    capture.release()
    assert ok
    found = make_detector("person").detect(frame)
    assert found and all(d.box[3] > d.box[2] for d in found)  # upright boxes
