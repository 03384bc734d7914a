"""What the closed-loop tests share: a small rendered sequence on disk."""
from __future__ import annotations

from pathlib import Path

import cv2
import pytest

from tracker.evaluation.synthetic import render_sequence


@pytest.fixture(scope="module")
def sequence(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A 640x360 OTB-style folder of 12 frames, a 40 px subject moving 6 px a frame."""
    folder = tmp_path_factory.mktemp("sequence")
    seq = render_sequence(frames=12, frame_size=(640, 360), target=40, speed=6.0)
    for i, image in enumerate(seq.frames, start=1):
        cv2.imwrite(str(folder / f"{i}.png"), image)
    (folder / "groundtruth_rect.txt").write_text("".join(",".join(f"{v:.2f}" for v in b) + "\n" for b in seq.boxes))
    return folder
