"""``gimbaltrack track --detect motion`` starts on a subject crossing the picture fast (a runner, a
cyclist) as soon as on a slow one: the motion detector reports it from its third frame (frame 2),
and its third sighting (frame 4) confirms it, on the subject. Until 2026-11-26 the confirmation
compared raw boxes, and a 40 px subject moving 9 to 16 px a frame did not start within these 30
frames (8 px a frame: at frame 8)."""
from __future__ import annotations

from pathlib import Path

import pytest

from pipelines.outputs.telemetry import read_telemetry
from tests.track.helpers import BOX, make_clip, run_track
from tracker.runtime.boxes import iou

SIZE = (640, 360)
FIRST_DETECTED = 2  # the motion detector needs three frames


@pytest.mark.parametrize("speed", [2, 9, 10, 12])  # px a frame; 2: the slow reference
def test_a_fast_subject_starts_as_soon_as_a_slow_one(tmp_path: Path, speed: int) -> None:
    def position(i: int) -> tuple[int, int]:
        return 20 + speed * i, 160

    clip = make_clip(tmp_path / "fast.avi", 30, position, size=SIZE)
    assert run_track(clip, tmp_path / "out", "--detect", "motion", "--no-video") == 0
    records = read_telemetry(tmp_path / "out" / "telemetry.jsonl")
    start = next(i for i, r in enumerate(records) if r["state"] != "acquiring")
    assert start <= FIRST_DETECTED + 2
    assert iou(tuple(records[start]["box"]), (*position(start), BOX, BOX)) > 0.5
