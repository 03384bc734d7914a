"""The whole closed loop on a short synthetic sequence (real time, simulated gimbal on a virtual bus)."""
import math

import pytest

from pipelines.closed_loop import LoopSettings, run_closed_loop


@pytest.mark.parametrize("tracker", ["oracle", "csrt-fast"])
def test_every_frame_gives_a_sample_and_a_command(sequence, tracker):
    result = run_closed_loop(sequence, LoopSettings(tracker=tracker, out_size=(480, 270), fps=60.0))
    frames = len(list(sequence.glob("*.png")))
    assert frames > 0 and len(result.steps) == frames
    first = result.steps[0].sample
    # at rest the view looks at the frame's centre: the subject starts left of it (x = 0.2 width)
    assert first.in_view and first.dx < 0
    assert all(math.isfinite(s.sample.dx) and math.isfinite(s.command.yaw_dps) for s in result.steps)
    assert result.summary["frames"] == frames and result.command_latencies
