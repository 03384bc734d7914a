"""The bundled demo clip, its ground truth and the script that makes them."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np

from pipelines.sources import open_source

SAMPLES = Path(__file__).parents[2] / "samples"


def _boxes(path: Path) -> np.ndarray:
    return np.loadtxt(path, delimiter=",", ndmin=2)


def test_clip_matches_its_ground_truth_and_roi() -> None:
    clip = SAMPLES / "demo.mp4"
    assert clip.stat().st_size < 2_000_000
    with open_source(str(clip)) as source:
        assert (source.size, source.fps) == ((640, 360), 30.0)
        count = sum(1 for _ in source)
    boxes = _boxes(SAMPLES / "demo_groundtruth.txt")
    assert count == len(boxes) == 270
    roi = [int(v) for v in (SAMPLES / "demo_roi.txt").read_text().split(",")]
    assert roi == [round(v) for v in boxes[0]]
    assert np.all(boxes[:, 0] >= 0) and np.all(boxes[:, 0] + boxes[:, 2] <= 640)
    assert np.all(boxes[:, 1] >= 0) and np.all(boxes[:, 1] + boxes[:, 3] <= 360)
    assert boxes[:, 2].max() / boxes[:, 2].min() > 1.4  # the subject grows
    centres = boxes[:, :2] + boxes[:, 2:] / 2
    steps = np.hypot(*np.diff(centres, axis=0).T)  # pixels per frame
    assert steps.max() < 10  # smooth
    assert steps.max() > 2.5 * np.median(steps) > 10 * steps.min()  # at varying speed


def test_wide_clip_matches_its_ground_truth_and_starts_off_centre() -> None:
    """The closed-loop demo's clip: the subject starts outside the central half a 640x360 view sees
    at rest (the virtual camera must start pointed at it) and crosses the frame."""
    clip = SAMPLES / "demo_wide.mp4"
    assert clip.stat().st_size < 3_000_000
    with open_source(str(clip)) as source:
        assert (source.size, source.fps) == ((1280, 720), 30.0)
        count = sum(1 for _ in source)
    boxes = _boxes(SAMPLES / "demo_wide_groundtruth.txt")
    assert count == len(boxes) == 180
    assert np.all(boxes[:, :2] >= 0) and np.all(boxes[:, 0] + boxes[:, 2] <= 1280)
    assert np.all(boxes[:, 1] + boxes[:, 3] <= 720)
    centres = boxes[:, :2] + boxes[:, 2:] / 2
    assert centres[0, 0] < 320 and centres[:, 0].max() > 960  # from outside the central half, across it
    assert np.hypot(*np.diff(centres, axis=0).T).max() < 10  # smooth


def test_script_reproduces_the_ground_truth(tmp_path: Path) -> None:
    result = subprocess.run([sys.executable, str(SAMPLES / "make_demo_clip.py"), "--out", str(tmp_path)],
                            capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    assert "fully hidden: frames" in result.stdout
    for name in ("demo_groundtruth.txt", "demo_roi.txt", "demo_wide_groundtruth.txt"):
        assert (tmp_path / name).read_text() == (SAMPLES / name).read_text()
    with open_source(str(tmp_path / "demo.mp4")) as source:
        assert sum(1 for _ in source) == 270
    with open_source(str(tmp_path / "demo_wide.mp4")) as source:
        assert sum(1 for _ in source) == 180
