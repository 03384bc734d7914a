"""What every frame source shares: the ``Frame``, the ``SourceError`` and the ``FrameSource`` base."""
from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Iterator
from dataclasses import dataclass
from types import TracebackType

import cv2
import numpy as np

from tracker.evaluation.datasets import ASSUMED_FPS


class SourceError(Exception):
    """A source cannot be opened or stopped delivering frames; the message is one line."""


@dataclass(frozen=True, slots=True, eq=False)
class Frame:
    """One BGR image, its capture time in seconds and its position in the source's sequence
    (compared by identity: the image is an array)."""

    image: np.ndarray
    timestamp: float
    index: int


class FrameSource(ABC):
    """An open source of frames: iterate it for ``Frame`` objects, close it when done.

    ``size`` is ``(width, height)``; ``fps`` and ``frame_count`` are ``None`` when unknown;
    ``dropped`` counts frames a live source discarded because the consumer was busy.
    """

    def __init__(self, description: str, size: tuple[int, int], fps: float | None,
                 frame_count: int | None, is_live: bool) -> None:
        self._description = description
        self._size = size
        self._fps = fps
        self._frame_count = frame_count
        self._is_live = is_live

    @property
    def description(self) -> str:
        return self._description

    @property
    def size(self) -> tuple[int, int]:
        return self._size

    @property
    def fps(self) -> float | None:
        return self._fps

    @property
    def playback_fps(self) -> float:
        """``fps``, or the rate assumed for a source that does not tell its own."""
        return self._fps or ASSUMED_FPS

    @property
    def frame_count(self) -> int | None:
        return self._frame_count

    @property
    def is_live(self) -> bool:
        return self._is_live

    @property
    def dropped(self) -> int:
        return 0

    @abstractmethod
    def read(self) -> Frame | None:
        """The next frame, or ``None`` at the end of a file; raises ``SourceError`` on failure."""

    @abstractmethod
    def close(self) -> None:
        """Release the underlying capture; safe to call more than once."""

    def __iter__(self) -> Iterator[Frame]:
        while (frame := self.read()) is not None:
            yield frame

    def __enter__(self) -> FrameSource:
        return self

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        self.close()

    def __repr__(self) -> str:
        return f"<{type(self).__name__} {self._description}>"


def nominal_fps(capture: cv2.VideoCapture) -> float | None:
    """The frame rate a capture reports, or ``None`` when it reports none or nonsense."""
    fps = capture.get(cv2.CAP_PROP_FPS)
    return fps if 0 < fps < 1000 else None
