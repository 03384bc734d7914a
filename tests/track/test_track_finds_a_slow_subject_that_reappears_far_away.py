"""A slow subject that vanishes and reappears far away, out of the template search's reach, is
found again by the motion detector. Its boxes of the slow checkered square come only every few
frames and shift, so they would not pass the 3-of-5 persistence a start needs; the tracker takes
a single detection that looks like the subject."""
from __future__ import annotations

from pathlib import Path

from pipelines.outputs.telemetry import read_telemetry
from tests.track.helpers import BOX, make_clip, run_track
from tracker.runtime.boxes import iou

SIZE = (680, 360)  # wide enough that the template search around where it was lost does not reach
GONE, BACK = 40, 90


def _subject(i: int) -> tuple[int, int] | None:
    """Drifting right at 2 px a frame, gone from frame GONE, back at once 460 px away at BACK."""
    if i < GONE:
        return 60 + 2 * i, 160
    return None if i < BACK else (600 - 2 * (i - BACK), 160)


def test_a_slow_subject_that_reappears_far_away_is_found_again(tmp_path: Path) -> None:
    clip = make_clip(tmp_path / "again.avi", 130, _subject, size=SIZE)
    assert run_track(clip, tmp_path / "out", "--detect", "motion", "--no-video") == 0
    records = read_telemetry(tmp_path / "out" / "telemetry.jsonl")
    states = [r["state"] for r in records]
    assert states[BACK - 1] == "lost"
    assert "tracking" in states[BACK:BACK + 20], "not found again within 20 frames"
    assert states[-1] == "tracking" and iou(tuple(records[-1]["box"]), (*_subject(len(records) - 1), BOX, BOX)) > 0.5
