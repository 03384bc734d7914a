"""While the subject is away, the detector finds another moving thing that does not look like it:
the tracker stays lost (the gimbal holds) rather than follow it, and takes the subject up again
when it comes back."""
from __future__ import annotations

from pathlib import Path

from pipelines.outputs.telemetry import read_telemetry
from tests.track.helpers import BOX, make_clip, out_right_and_back, run_track
from tracker.boxes import iou

BACK_AT = 60  # the frame where the subject starts to come back in from the right


_subject = out_right_and_back(BACK_AT, 60)


def _other(i: int) -> tuple[int, int] | None:
    """Another thing, striped, that walks in from the left at frame 25 and crosses the picture."""
    return (-BOX + 3 * (i - 25), 150) if i >= 25 else None


def test_a_lost_subject_is_not_swapped_for_another_moving_thing(tmp_path: Path) -> None:
    clip = make_clip(tmp_path / "other.avi", 100, _subject, other=_other)
    assert run_track(clip, tmp_path / "out", "--detect", "motion", "--no-video") == 0
    records = read_telemetry(tmp_path / "out" / "telemetry.jsonl")
    states = [r["state"] for r in records]
    assert "lost" in states[:BACK_AT]
    tracking = [(i, r["box"]) for i, r in enumerate(records) if r["state"] == "tracking"]
    off = [i for i, box in tracking if _subject(i) is None or iou(tuple(box), (*_subject(i), BOX, BOX)) < 0.3]
    assert off == [], "followed something that is not the subject"
    assert states[-1] == "tracking", "the subject was not taken up again"
