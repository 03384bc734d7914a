"""What the closed-loop tests share: a small rendered sequence on disk."""
from __future__ import annotations

from pathlib import Path

import pytest

from tests.support import write_sequence_folder
from tracker.evaluation.synthetic import render_sequence


@pytest.fixture(scope="module")
def sequence(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A 640x360 OTB-style folder of 12 frames, a 40 px subject moving 6 px a frame."""
    folder = tmp_path_factory.mktemp("sequence")
    seq = render_sequence(frames=12, frame_size=(640, 360), target=40, speed=6.0)
    return write_sequence_folder(folder, seq.frames, seq.boxes)
