"""While the subject is away, the detector finds another moving thing that does not look like it:
the tracker stays lost (the gimbal holds) rather than follow it, and takes the subject up again
when it comes back."""
from __future__ import annotations

from pathlib import Path

from pipelines.outputs.telemetry import read_telemetry
from tests.track.helpers import BOX, SIZE, make_clip, out_right_and_back, run_track
from tracker.runtime.boxes import Box

BACK_AT = 60  # the frame where the subject starts to come back in from the right


_subject = out_right_and_back(BACK_AT, 60)


def _other(i: int) -> tuple[int, int] | None:
    """Another thing, striped, that walks in from the left at frame 25 and crosses the picture."""
    return (-BOX + 3 * (i - 25), 150) if i >= 25 else None


def _share_on_subject(box: Box, i: int) -> float:
    """How much of the box's part inside the frame covers the subject's (0 when it is away): a
    subject coming in at the edge is only partly in view, and so is a box following it."""
    where = _subject(i)
    if where is None:
        return 0.0
    x0, y0, x1, y1 = max(box[0], 0), max(box[1], 0), min(box[0] + box[2], SIZE[0]), min(box[1] + box[3], SIZE[1])
    sx1, sy1 = min(where[0] + BOX, SIZE[0]), min(where[1] + BOX, SIZE[1])
    seen = max(x1 - x0, 0) * max(y1 - y0, 0)
    on = max(min(x1, sx1) - max(x0, where[0]), 0) * max(min(y1, sy1) - max(y0, where[1]), 0)
    return on / seen if seen else 0.0


def test_a_lost_subject_is_not_swapped_for_another_moving_thing(tmp_path: Path) -> None:
    clip = make_clip(tmp_path / "other.avi", 100, _subject, other=_other)
    assert run_track(clip, tmp_path / "out", "--detect", "motion", "--no-video") == 0
    records = read_telemetry(tmp_path / "out" / "telemetry.jsonl")
    states = [r["state"] for r in records]
    assert "lost" in states[:BACK_AT]
    tracking = [(i, r["box"]) for i, r in enumerate(records) if r["state"] == "tracking"]
    off = [i for i, box in tracking if _share_on_subject(box, i) < 0.5]
    assert off == [], "followed something that is not the subject"
    assert states[-1] == "tracking", "the subject was not taken up again"


def test_a_file_at_file_speed_gives_the_same_boxes_every_run(tmp_path: Path) -> None:
    """The tracker runs on the video's time, not on how fast the machine reads the file: when it
    ran on the time each frame was read, no two runs of this clip had the same boxes, and on a
    loaded machine about one in six took the other thing for the subject."""
    clip = make_clip(tmp_path / "other.avi", 100, _subject, other=_other)
    runs = []
    for run in ("first", "second"):
        assert run_track(clip, tmp_path / run, "--detect", "motion", "--no-video") == 0
        runs.append([(r["state"], r.get("box")) for r in read_telemetry(tmp_path / run / "telemetry.jsonl")])
    assert runs[0] == runs[1]
