"""The virtual camera starts pointed at the subject's first box, wherever it is in the wide frame."""
from __future__ import annotations

from pathlib import Path

import pytest

from pipelines.loop.closed_loop import LoopSettings, run_closed_loop
from tests.support import write_sequence_folder
from tracker.evaluation.synthetic import render_sequence


@pytest.fixture(scope="module")
def edge_start(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A 1280x720 sequence whose 40 px subject starts at x = 256, outside the central 640x360
    view a gimbal at rest would see (the case of dtb70_gull2)."""
    folder = tmp_path_factory.mktemp("edge_start")
    seq = render_sequence(frames=10, frame_size=(1280, 720), target=40, speed=4.0)
    return write_sequence_folder(folder, seq.frames, seq.boxes)


@pytest.mark.parametrize("tracker", ["oracle", "dcf"])
def test_a_subject_at_the_wide_frames_edge_starts_centred(edge_start: Path, tracker: str) -> None:
    result = run_closed_loop(edge_start, LoopSettings(tracker=tracker, fps=60.0))
    first = result.steps[0].sample
    assert first.in_view and abs(first.dx) < 0.01 and abs(first.dy) < 0.01
    assert result.summary["out_of_view"] == 0.0
