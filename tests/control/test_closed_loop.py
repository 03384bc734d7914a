"""The whole closed loop on a short synthetic sequence (real time, simulated gimbal on a virtual bus)."""
import math
import shutil
from pathlib import Path

import pytest

from pipelines.loop.closed_loop import LoopSettings, run_closed_loop

FAST = LoopSettings(out_size=(480, 270), fps=60.0)  # oracle detections


def without_truth(sequence: Path, folder: Path, lines: dict[int, str]) -> Path:
    """A copy of ``sequence`` in ``folder`` with the ground-truth lines numbered in ``lines`` replaced."""
    shutil.copytree(sequence, folder)
    path = folder / "groundtruth_rect.txt"
    rows = path.read_text().splitlines()
    for number, text in lines.items():
        rows[number - 1] = text
    path.write_text("\n".join(rows) + "\n")
    return folder


@pytest.mark.parametrize("tracker", ["oracle", "csrt-fast"])
def test_every_frame_gives_a_sample_and_a_command(sequence, tracker):
    result = run_closed_loop(sequence, LoopSettings(tracker=tracker, out_size=(480, 270), fps=60.0))
    frames = len(list(sequence.glob("*.png")))
    assert frames > 0 and len(result.steps) == frames
    first = result.steps[0].sample
    # the gimbal starts pointed at the first box (x = 0.2 width), not at the frame's centre
    assert first.in_view and abs(first.dx) < 0.01 and abs(first.dy) < 0.01
    assert all(math.isfinite(s.sample.dx) and math.isfinite(s.command.yaw_dps) for s in result.steps)
    assert result.summary["frames"] == result.summary["frames_scored"] == frames and result.command_latencies


def test_frames_without_truth_are_neither_scored_nor_detected(sequence, tmp_path):
    """NaN and 0,0,0,0 lines (how OTB, VOT and UAV123 mark an unseen subject) are left out of the
    scores (they once counted as out of view: error 1.0, or a subject in the source's corner), and
    the oracle has no detection on them."""
    gapped = without_truth(sequence, tmp_path / "gapped", {5: "NaN,NaN,NaN,NaN", 6: "nan,nan,nan,nan",
                                                           7: "0,0,0,0", 8: "0,0,0,0"})
    result = run_closed_loop(gapped, FAST)
    unscored = [i for i, step in enumerate(result.steps) if step.sample is None]
    assert unscored == [4, 5, 6, 7]
    assert all(result.steps[i].command.mode != "track" for i in unscored)
    assert [step.t for step in result.steps] == sorted(step.t for step in result.steps)
    assert result.summary["frames"] == 12 and result.summary["frames_scored"] == 8
    assert result.summary["out_of_view"] == 0.0


def test_a_run_without_truth_to_score_or_start_on_is_refused(sequence, tmp_path):
    none = without_truth(sequence, tmp_path / "none", {n: "NaN,NaN,NaN,NaN" for n in range(1, 13)})
    with pytest.raises(ValueError, match="no ground truth, cannot measure centring"):
        run_closed_loop(none, FAST)
    late = without_truth(sequence, tmp_path / "late", {1: "0,0,0,0"})
    with pytest.raises(ValueError, match="the first ground-truth box .* is missing or empty"):
        run_closed_loop(late, LoopSettings(tracker="csrt-fast"))  # the tracker starts on it
    result = run_closed_loop(late, FAST)  # the oracle starts when the subject shows up
    assert result.steps[0].sample is None and result.steps[0].command.mode == "idle"
    assert result.summary["frames_scored"] == 11
