"""A ground-truth file without a single box."""
from pathlib import Path

import pytest

from tracker.evaluation.datasets import parse_groundtruth


@pytest.mark.parametrize("text", ["", "\n", " \r\n\n"], ids=["empty", "one-blank-line", "blank-lines-crlf"])
def test_a_file_without_boxes_is_an_error(tmp_path: Path, text: str) -> None:
    """An empty annotation would otherwise make a sequence of no frames."""
    (tmp_path / "gt.txt").write_text(text)
    with pytest.raises(ValueError, match="gt.txt: no ground-truth boxes"):
        parse_groundtruth(tmp_path / "gt.txt")
