"""A subject lost while the camera turns (a gimbal still panning after it) is found again by the
motion detector when it comes back: the detector runs while the picture itself moves."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from pipelines.outputs.telemetry import read_telemetry
from tests.support import write_clip
from tests.track.helpers import BOX, run_track
from tracker.runtime.boxes import iou
from tracker.evaluation.synthetic import texture

SIZE = (680, 360)  # wide enough that the template search around where it was lost does not reach
FRAMES, GONE, BACK = 130, 40, 90
PAN = 4  # px a frame, from GONE on: the camera turns to the left, so the scene moves right in the image


def _view(i: int) -> int:
    """Where the view's left edge is in the scene."""
    return PAN * (FRAMES - max(i, GONE))


def _subject(i: int) -> tuple[int, int] | None:
    """Its top-left in the image: walking right at 4 px a frame, gone from GONE, back at BACK 460 px
    away, drifting left (against the pan: 6 px a frame over the scene)."""
    if i < GONE:
        return 60 + 4 * i, 160
    return None if i < BACK else (600 - 2 * (i - BACK), 160)


def _clip(path: Path) -> Path:
    width, height = SIZE
    rng = np.random.default_rng(7)
    scene = texture(height, width + _view(0), rng, cell=16, contrast=0.35)  # as the rendered sequences'
    tile = np.indices((BOX, BOX)).sum(axis=0) // 8 % 2
    look = np.where(tile[..., None] == 1, (20, 40, 230), (240, 240, 30)).astype(np.uint8)

    def image(i: int) -> np.ndarray:
        frame = scene[:, _view(i):_view(i) + width].copy()
        where = _subject(i)
        if where is not None:
            x, y = where
            frame[y:y + BOX, x:x + BOX] = look
        return frame

    return write_clip(path, (image(i) for i in range(FRAMES)), 30.0, "MJPG")


def test_a_subject_lost_while_the_camera_pans_is_found_again(tmp_path: Path) -> None:
    clip = _clip(tmp_path / "pan.avi")
    assert run_track(clip, tmp_path / "out", "--detect", "motion", "--no-video") == 0
    records = read_telemetry(tmp_path / "out" / "telemetry.jsonl")
    states = [r["state"] for r in records]
    assert "tracking" in states[:GONE] and states[BACK - 1] == "lost", states
    assert "tracking" in states[BACK:BACK + 20], "not found again within 20 frames"
    assert states[-1] == "tracking" and iou(tuple(records[-1]["box"]), (*_subject(FRAMES - 1), BOX, BOX)) > 0.5
