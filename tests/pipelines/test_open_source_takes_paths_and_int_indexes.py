"""``open_source`` takes a path object and an int camera index as well as strings (both were an
AttributeError on ``.strip``), and names any other type in a SourceError."""
from __future__ import annotations

from pathlib import Path

import pytest

from pipelines.sources import SourceError, open_source


def test_a_path_object_opens_like_its_string(small_video: Path) -> None:
    with open_source(small_video) as by_path, open_source(str(small_video)) as by_text:
        assert [f.index for f in by_path] == [f.index for f in by_text]


def test_a_missing_path_object_is_named(tmp_path: Path) -> None:
    with pytest.raises(SourceError, match="no such video file or image folder"):
        open_source(tmp_path / "missing.mp4")


def test_an_int_index_is_a_camera() -> None:
    with pytest.raises(SourceError, match="camera 97 does not open"):
        open_source(97)


@pytest.mark.parametrize("spec", [None, 1.5, True, b"clip.mp4"])
def test_other_types_are_named(spec: object) -> None:
    with pytest.raises(SourceError, match="a source is a path, camera index or stream URL, not"):
        open_source(spec)  # type: ignore[arg-type]
