"""Detectors: motion on rendered frames; face and person construct and run."""
from __future__ import annotations

import subprocess
import sys

import cv2
import numpy as np
import pytest

from tracker.detectors import Detection, HaarFaceDetector, HogPersonDetector, MotionDetector, make_detector
from tracker.detectors.camera_motion import camera_motion
from tracker.evaluation.synthetic import render_sequence, texture
from tracker.runtime.boxes import iou


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


def _moving_square(look: np.ndarray, frames: int, still: int = 0, noise: float = 0.0, step: int = 10, x0: int = 60,
                   seed: int = 0) -> tuple[list[np.ndarray], list[tuple[int, int, int, int] | None]]:
    """A static textured scene for ``still`` frames, then ``look`` (a square) moving ``step`` px a frame to
    the right from ``x0``; its boxes (None while it is not there). ``noise``: sensor noise's sigma in grey levels."""
    rng = np.random.default_rng(seed)
    background = texture(240, 320, rng, cell=16, contrast=0.35)
    size = look.shape[0]
    images, boxes = [background.copy() for _ in range(still)], [None] * still
    for i in range(frames):
        image = background.copy()
        x = x0 + step * i
        image[100:100 + size, x:x + size] = look
        images.append(image)
        boxes.append((x, 100, size, size))
    if noise:
        images = [np.clip(f + rng.normal(0.0, noise, f.shape), 0, 255).astype(np.uint8) for f in images]
    return images, boxes


def _boxes(frames: list[np.ndarray]) -> list[list[tuple[float, ...]]]:
    """The motion detector's boxes in each frame, largest first."""
    detector = make_detector("motion")
    return [[d.box for d in detector.detect(f)] for f in frames]


def _first_boxes(frames: list[np.ndarray]) -> list[tuple[float, ...] | None]:
    return [found[0] if found else None for found in _boxes(frames)]


def _close(found, truth, tolerance: float = 3.0) -> bool:
    return found is not None and max(abs(a - b) for a, b in zip(found, truth)) <= tolerance


TEXTURED = texture(40, 40, np.random.default_rng(1), cell=6, contrast=1.0)
FLAT = np.full((40, 40, 3), 235, np.uint8)


@pytest.mark.parametrize("look", [TEXTURED, FLAT], ids=["textured", "flat"])
def test_motion_boxes_an_object_where_it_is_now(look):
    """A 40 px square moving 10 px a frame into a watched scene: its box, not the ground it left
    (52 px wide, textured) nor two edge strips, the first the trailing one (flat-coloured)."""
    frames, truth = _moving_square(look, frames=8, still=5, noise=2.0)
    found = _first_boxes(frames)
    assert all(_close(f, t) for f, t in zip(found[7:], truth[7:])), list(zip(found[7:], truth[7:]))


def test_motion_boxes_an_object_moving_from_the_first_frame_where_it_is_once_it_has_left_its_start():
    seq = render_sequence(frames=20, speed=6.0, seed=8)
    found = _first_boxes(seq.frames)
    ious = [iou(f, t) if f else 0.0 for f, t in zip(found[10:], seq.boxes[10:])]
    assert min(ious) > 0.85, ious  # three-frame differencing alone: 0.76-0.83


def test_motion_forgets_where_a_still_subject_stood_once_it_walks_off():
    """Learnt as background while it stood: once clear of that spot, the spot is not reported."""
    still, _ = _moving_square(TEXTURED, frames=4, step=0)
    walk, truth = _moving_square(TEXTURED, frames=10, step=10)
    found = _boxes(still + walk)[4:]
    assert all(len(f) == 1 and _close(f[0], t) for f, t in zip(found[6:], truth[6:])), list(zip(found[6:], truth[6:]))


def test_motion_starts_afresh_after_a_change_over_the_whole_picture():
    """Light switched on (or the camera moved): the background is learnt again from the next three frames,
    instead of over ``settle_frames`` with the whole picture one blob meanwhile."""
    frames, truth = _moving_square(TEXTURED, frames=6, still=14)  # brighter from frame 8, the square from 14
    found = _first_boxes(frames[:8] + [cv2.add(f, 40) for f in frames[8:]])
    assert all(f is None for f in found[9:14])
    assert all(_close(f, t) for f, t in zip(found[16:], truth[16:])), list(zip(found[16:], truth[16:]))


def test_motion_ignores_sensor_noise():
    frames, _ = _moving_square(TEXTURED, frames=40, step=0, noise=4.0)
    assert _first_boxes(frames) == [None] * 40


def test_motion_restarts_when_the_frame_size_changes():
    frames = render_sequence(frames=8, speed=6.0, seed=8).frames
    small = render_sequence(frames=8, frame_size=(160, 120), speed=3.0, seed=8).frames
    detector = make_detector("motion")
    found = [detector.detect(f) for f in frames[:4] + small]
    assert found[4] == found[5] == [] and all(found[6:])  # three frames of the new size, then it reports


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


# An empty frame (no pixels) gives no candidates, for the motion and face detectors as for the
# person detector (whose case runs in a child process in test_detectors.py).
@pytest.mark.parametrize("kind", ["motion", "face"])
@pytest.mark.parametrize("shape", [(0, 0, 3), (0, 5), (5, 0, 4)])
def test_an_empty_frame_gives_nothing(kind: str, shape: tuple[int, ...]) -> None:
    assert make_detector(kind).detect(np.zeros(shape, np.uint8)) == []


# The OpenCV face and person detectors' answers as candidates: boxes in the frame's own pixels
# (the person detector works on frames shrunk to 640 px) and the best candidate first. OpenCV's own
# detectors are replaced by stand-ins with known answers (the synthetic frames hold no faces or people).
class _Hog:
    """Stands in for ``cv2.HOGDescriptor``: two people, in the pixels of the image it is given."""

    winSize = (64, 128)

    def __init__(self) -> None:
        self.shapes: list[tuple[int, ...]] = []

    def detectMultiScale(self, image: np.ndarray, **options: object) -> tuple[np.ndarray, np.ndarray]:
        self.shapes.append(image.shape)
        return np.array([[10, 20, 64, 128], [300, 40, 80, 160]]), np.array([[-0.5], [1.5]])


class _Cascade:
    """Stands in for ``cv2.CascadeClassifier``: two faces, the second merged from more raw hits."""

    def detectMultiScale2(self, image: np.ndarray, **options: object) -> tuple[np.ndarray, np.ndarray]:
        return np.array([[10, 10, 30, 30], [100, 50, 40, 40]]), np.array([3, 12])


def test_person_boxes_are_in_the_frames_pixels_and_best_first(monkeypatch: pytest.MonkeyPatch) -> None:
    detector = HogPersonDetector()
    hog = _Hog()
    monkeypatch.setattr(detector, "_hog", hog)
    found = detector.detect(np.zeros((720, 1280, 3), np.uint8))
    assert hog.shapes == [(360, 640, 3)]  # shrunk by 2
    assert [d.box for d in found] == [(600.0, 80.0, 160.0, 320.0), (20.0, 40.0, 128.0, 256.0)]
    assert found[0].score > found[1].score


def test_faces_are_best_first(monkeypatch: pytest.MonkeyPatch) -> None:
    detector = HaarFaceDetector()
    monkeypatch.setattr(detector, "_cascade", _Cascade())
    found = detector.detect(np.zeros((240, 320, 3), np.uint8))
    assert [d.box for d in found] == [(100.0, 50.0, 40.0, 40.0), (10.0, 10.0, 30.0, 30.0)]
    assert 0.0 < found[1].score < found[0].score < 1.0


# The motion detector's blobs: a moving speck smaller than ``min_area_fraction`` of the picture is
# not a candidate, and each blob's score is its share of the moving area.
RNG = np.random.default_rng(12)
BIG, SMALL = texture(40, 40, RNG, cell=5, contrast=1.0), texture(20, 20, RNG, cell=4, contrast=1.0)


def _last_detections(speck: int = 0) -> list[Detection]:
    """What a motion detector reports on the fourth frame of a grey scene where a 40 px square moves
    12 px a frame, with either a 20 px square or (``speck`` > 0) a white speck of that side moving too."""
    detector = make_detector("motion")
    found: list[Detection] = []
    for i in range(4):
        frame = np.full((240, 320, 3), 128, np.uint8)
        frame[100:140, 40 + 12 * i:80 + 12 * i] = BIG
        if speck:
            frame[20 + 6 * i:20 + 6 * i + speck, 250:250 + speck] = 255
        else:
            frame[180:200, 200 + 10 * i:220 + 10 * i] = SMALL
        found = detector.detect(frame)
    return found


def test_a_moving_speck_is_not_a_candidate() -> None:
    found = _last_detections(speck=3)  # a few dozen moving pixels at most, under 0.05 % of 320 x 240
    assert len(found) == 1 and 60 < found[0].box[0] < 80


def test_each_blob_scores_its_share_of_the_moving_area() -> None:
    big, small = _last_detections()
    assert big.score + small.score == pytest.approx(1.0)
    assert big.score / small.score == pytest.approx(big.box[2] * big.box[3] / (small.box[2] * small.box[3]), rel=0.3)


# A frame only a pixel or two high once worked on (a wide strip: 1000 x 2 shrinks to 640 x 1):
# the camera-motion fit, which halves images over 400 px, cannot halve it and must not fail.
@pytest.mark.parametrize("shape", [(1, 1000, 3), (2, 1000, 3), (1000, 1, 3)])
def test_the_motion_detector_takes_a_thin_strip(shape: tuple[int, int, int]) -> None:
    rng = np.random.default_rng(0)
    detector = MotionDetector()
    for _ in range(4):  # a still camera worked on these before the camera-motion fit came
        assert isinstance(detector.detect(rng.integers(0, 256, shape, dtype=np.uint8)), list)


def test_a_one_pixel_high_image_gives_no_camera_motion() -> None:
    strip = np.random.default_rng(1).integers(0, 256, (1, 401), dtype=np.uint8)
    assert camera_motion(strip, np.roll(strip, 3, axis=1)) is None


# ``MotionDetector(settle_frames=...)`` takes 1..255 (a pixel's age is counted in a byte).
@pytest.mark.parametrize("frames", [0, 256])
def test_settle_frames_out_of_range_is_refused(frames: int) -> None:
    with pytest.raises(ValueError, match="settle_frames must be 1..255"):
        MotionDetector(settle_frames=frames)


@pytest.mark.parametrize("frames", [1, 255])
def test_settle_frames_at_the_ends_of_the_range_is_taken(frames: int) -> None:
    MotionDetector(settle_frames=frames)
