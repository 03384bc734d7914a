"""What the eval batch tests share: rendered OTB-style sequences and the scores that must not
depend on how the sequences were run."""
from __future__ import annotations

from pathlib import Path

import cv2

from pipelines.batch import Outcome
from tracker.evaluation.synthetic import render_sequence


def write_otb(folder: Path, frames: int, seed: int) -> Path:
    """A rendered OTB-style sequence (its own subject path for each ``seed``)."""
    seq = render_sequence(frames=frames, seed=seed)
    (folder / "img").mkdir(parents=True)
    for i, frame in enumerate(seq.frames, 1):
        cv2.imwrite(str(folder / "img" / f"{i:04d}.png"), frame)
    (folder / "groundtruth_rect.txt").write_text("".join(",".join(f"{v:.1f}" for v in b) + "\n" for b in seq.boxes))
    return folder


def scores(outcomes: list[Outcome]) -> list[tuple]:
    """What must not depend on how the sequences were run: every box and both scores."""
    return [(o.name, o.result.frames, o.result.boxes, o.result.prec20, o.result.auc) for o in outcomes]
