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


def long_sequence(folder: Path, count: int = 3000) -> Path:
    """The same two images ``count`` times over: a run of many seconds."""
    frames = render_sequence(frames=2, seed=3)
    (folder / "img").mkdir(parents=True)
    for i in range(1, 3):
        cv2.imwrite(str(folder / f"{i}.png"), frames.frames[i - 1])
    for i in range(1, count + 1):
        (folder / "img" / f"{i:05d}.png").symlink_to(folder / f"{i % 2 + 1}.png")
    box = ",".join(f"{v:.1f}" for v in frames.boxes[0])
    (folder / "groundtruth_rect.txt").write_text(f"{box}\n" * count)
    return folder
