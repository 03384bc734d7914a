"""A file source read again after its end or after a decode error returns ``None`` at once, never
waits for a decoder thread that has already finished."""
from __future__ import annotations

import threading
from collections.abc import Callable
from pathlib import Path

import cv2
import pytest

from pipelines.sources import FrameSource, SourceError, open_source


def _read_again(source: FrameSource) -> list[object]:
    """``source.read()`` on a helper thread: what it returned, or nothing if it is still waiting."""
    result: list[object] = []
    reader = threading.Thread(target=lambda: result.append(source.read()), daemon=True)
    reader.start()
    reader.join(5.0)
    return result


def test_a_read_after_the_end_is_none(small_video: Path) -> None:
    with open_source(str(small_video)) as source:
        assert len(list(source)) == 12
        assert _read_again(source) == [None]


def test_a_read_after_a_decode_error_is_none(tmp_path: Path, frame_image: Callable[..., object]) -> None:
    for i, size in enumerate([(96, 64), (80, 64), (96, 64)]):
        cv2.imwrite(str(tmp_path / f"{i:04d}.png"), frame_image(i, size))
    with open_source(str(tmp_path)) as source:
        assert source.read() is not None
        with pytest.raises(SourceError, match="0001.png is 80x64"):
            source.read()
        assert _read_again(source) == [None]
