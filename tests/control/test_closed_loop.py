"""The whole closed loop on a short synthetic sequence (real time, simulated gimbal on a virtual bus)."""
import math

import cv2
import pytest

from pipelines.closed_loop import LoopSettings, run_closed_loop
from tracker.synthetic import render_sequence

FRAMES = 12


@pytest.fixture(scope="module")
def sequence(tmp_path_factory):
    folder = tmp_path_factory.mktemp("loop")
    seq = render_sequence(frames=FRAMES, frame_size=(640, 360), target=40, speed=6.0)
    for i, (image, box) in enumerate(zip(seq.frames, seq.boxes), start=1):
        cv2.imwrite(str(folder / f"{i}.png"), image)
    (folder / "groundtruth_rect.txt").write_text("".join(",".join(f"{v:.2f}" for v in b) + "\n" for b in seq.boxes))
    return folder


@pytest.mark.parametrize("tracker", ["oracle", "csrt-fast"])
def test_every_frame_gives_a_sample_and_a_command(sequence, tracker):
    result = run_closed_loop(sequence, LoopSettings(tracker=tracker, out_size=(480, 270), fps=60.0))
    assert len(result.steps) == FRAMES
    first = result.steps[0].sample
    # at rest the view looks at the frame's centre: the subject starts left of it (x = 0.2 width)
    assert first.in_view and first.dx < 0
    assert all(math.isfinite(s.sample.dx) and math.isfinite(s.command.yaw_dps) for s in result.steps)
    assert result.summary["frames"] == FRAMES and result.command_latencies
