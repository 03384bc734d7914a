"""Ground truth written with spaces between the values."""
from pathlib import Path

from tracker.evaluation.datasets import parse_groundtruth


def test_space_separated_boxes_and_polygons(tmp_path: Path) -> None:
    (tmp_path / "gt.txt").write_text("1 2 3 4\n5  6 7 8\n1 1 5 1 5 4 1 4\n")
    assert parse_groundtruth(tmp_path / "gt.txt") == ((1, 2, 3, 4), (5, 6, 7, 8), (1, 1, 4, 3))
