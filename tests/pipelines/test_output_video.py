"""The annotated video: drawing, frame count on read-back, size checks and crash tolerance of .avi."""
from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import cv2
import numpy as np
import pytest

from pipelines.outputs.annotated_video import (
    AnnotatedVideoWriter, BackgroundVideoWriter, STATE_COLOURS, annotate, video_size,
)
from pipelines.sources import open_source
from tests.support import wait_until
from tracker.runtime.estimate import TargetEstimate, TrackState


def _estimate(index: int, state: TrackState = TrackState.TRACKING) -> TargetEstimate:
    return TargetEstimate((20.0 + index, 30.0, 40.0, 50.0), (0.0, 0.0), 0.9, state, index / 30, index)


def test_annotate_draws_box_in_the_state_colour_without_touching_the_input() -> None:
    image = np.zeros((240, 320, 3), np.uint8)
    estimate = TargetEstimate((200.0, 150.0, 60.0, 50.0), (0.0, 0.0), 0.2, TrackState.LOST, 0.0, 0)
    out = annotate(image, estimate, rates_dps=(12.0, -3.5), lines=["extra"])
    assert not image.any()
    assert tuple(out[175, 200]) == STATE_COLOURS[TrackState.LOST]  # left edge of the box
    assert tuple(out[200, 230]) == STATE_COLOURS[TrackState.LOST]  # bottom edge
    assert tuple(out[175, 230]) == STATE_COLOURS[TrackState.LOST]  # subject centre cross
    assert out[140, 185].any()  # on the error vector from (160, 120) to (230, 175)
    assert out[10:60, 10:100].any()  # the text block


def test_annotate_without_copy_draws_on_the_image_itself() -> None:
    image = np.zeros((240, 320, 3), np.uint8)
    out = annotate(image, _estimate(1), copy=False)
    assert out is image and image.any()


@pytest.mark.parametrize("max_width", [None, 80])
def test_writing_leaves_the_callers_frame_untouched(tmp_path: Path, max_width: int | None) -> None:
    """Full size, annotate copies; shrunk, it draws on the writer's own shrunk frame."""
    image = np.zeros((120, 160, 3), np.uint8)
    with AnnotatedVideoWriter(tmp_path / "a.avi", (160, 120), 30.0, max_width) as writer:
        writer.write(image, _estimate(1), (1.0, 2.0), ["mode track"])
    assert not image.any()


def test_video_reads_back_with_every_frame(tmp_path: Path, frame_image: Callable[..., np.ndarray]) -> None:
    path = tmp_path / "annotated.mp4"
    with AnnotatedVideoWriter(path, (160, 120), 30.0) as writer:
        for index in range(15):
            estimate = _estimate(index) if index % 3 else None
            writer.write(frame_image(index, (160, 120)), estimate, (1.0, 2.0) if estimate else None)
        assert writer.frames == 15
    with open_source(str(path)) as source:
        assert source.size == (160, 120) and source.fps == 30.0
        assert len(list(source)) == 15


def test_wrong_frame_size_and_unknown_container_are_refused(tmp_path: Path) -> None:
    with AnnotatedVideoWriter(tmp_path / "a.mp4", (160, 120), 30.0) as writer:
        with pytest.raises(ValueError, match="frame is 80x60, video is 160x120"):
            writer.write(np.zeros((60, 80, 3), np.uint8))
    with pytest.raises(ValueError, match="must end in .mp4 or .avi"):
        AnnotatedVideoWriter(tmp_path / "a.mkv", (160, 120), 30.0)
    with pytest.raises(OSError, match="cannot write video"):
        AnnotatedVideoWriter(tmp_path / "missing" / "a.mp4", (160, 120), 30.0)


def test_avi_stays_readable_when_the_process_dies(tmp_path: Path, run_and_crash: Callable[[str], None]) -> None:
    path = tmp_path / "annotated.avi"
    run_and_crash(f"""
        import numpy as np
        from pipelines.outputs.annotated_video import AnnotatedVideoWriter
        writer = AnnotatedVideoWriter({str(path)!r}, (160, 120), 30.0)
        rng = np.random.default_rng(0)
        for _ in range(100):
            writer.write(rng.integers(0, 256, (120, 160, 3), dtype=np.uint8))
    """)
    capture = cv2.VideoCapture(str(path))
    count = 0
    while capture.read()[0]:
        count += 1
    assert count >= 60  # all but what was still in FFmpeg's write buffer (~25 frames of noise here)


def test_background_writer_keeps_every_frame_in_order(tmp_path):
    path = tmp_path / "bg.avi"
    with BackgroundVideoWriter(path, (64, 48), 10.0, queue_size=2) as writer:
        for i in range(25):
            writer.write(np.full((48, 64, 3), i * 10, np.uint8))
    assert writer.frames == 25
    capture = cv2.VideoCapture(str(path))
    means = []
    while (frame := capture.read())[0]:
        means.append(float(frame[1][40:, 50:].mean()))  # a corner the annotation leaves alone
    capture.release()
    assert len(means) == 25
    assert all(b > a for a, b in zip(means, means[1:]))


def test_background_writer_reports_a_worker_failure_once(tmp_path):
    writer = BackgroundVideoWriter(tmp_path / "bad.avi", (64, 48), 10.0)
    writer.write(np.zeros((10, 10, 3), np.uint8))  # wrong size: fails in the worker thread
    with pytest.raises(ValueError, match="frame is 10x10"):
        writer.close()  # drains the queue, then reports what failed
    writer.close()  # already reported: quiet


@pytest.mark.parametrize("size, max_width, expected", [
    ((1280, 720), 640, (640, 360)),
    ((1920, 1080), 640, (640, 360)),
    ((1000, 563), 640, (640, 360)),  # even sides for the encoder
    ((640, 360), 640, (640, 360)),
    ((320, 240), 640, (320, 240)),  # never enlarged
    ((1280, 720), None, (1280, 720)),
])
def test_video_size_shrinks_wide_frames_to_even_sides(size, max_width, expected) -> None:
    assert video_size(size, max_width) == expected


def test_shrunk_video_keeps_the_annotation_on_the_subject(tmp_path: Path) -> None:
    path = tmp_path / "small.avi"
    estimate = TargetEstimate((200.0, 100.0, 80.0, 60.0), (0.0, 0.0), 0.9, TrackState.LOST, 0.0, 0)
    with AnnotatedVideoWriter(path, (320, 240), 30.0, max_width=160) as writer:
        assert writer.video_size == (160, 120)
        writer.write(np.zeros((240, 320, 3), np.uint8), estimate)
    ok, frame = cv2.VideoCapture(str(path)).read()
    assert ok and frame.shape == (120, 160, 3)
    # the box's left edge at x = 200 / 2, between y = 50 and 80, in red (lossy: roughly)
    edge = frame[55:75, 99:102].reshape(-1, 3).mean(axis=0)
    assert edge[2] > 120 and edge[0] < 80 and edge[1] < 80
    with pytest.raises(ValueError, match="max_width must be at least 2"):
        AnnotatedVideoWriter(tmp_path / "bad.avi", (320, 240), 30.0, max_width=1)


# BackgroundVideoWriter: a failure in its worker reaches the next ``write`` (so a run ends when its
# video cannot be written, not only at the end), once.
def test_a_worker_failure_is_raised_by_a_later_write(tmp_path: Path) -> None:
    writer = BackgroundVideoWriter(tmp_path / "bad.avi", (64, 48), 10.0)
    writer.write(np.zeros((10, 10, 3), np.uint8))  # wrong size: fails in the worker thread
    good = np.zeros((48, 64, 3), np.uint8)

    def write_fails() -> bool:
        try:
            writer.write(good)
        except ValueError as exc:
            assert "frame is 10x10" in str(exc)
            return True
        return False

    assert wait_until(write_fails, timeout=10.0)
    writer.write(good)  # already reported: quiet, and the worker keeps draining
    writer.close()
