"""Recorded sources: a video file or a folder of images, read as fast as pulled or paced in real time."""
from __future__ import annotations

import queue
import threading
import time
from abc import abstractmethod
from collections.abc import Callable
from pathlib import Path

import cv2
import numpy as np

from pipelines.sources.base import Frame, FrameSource, SourceError, nominal_fps
from tracker.evaluation.datasets import ASSUMED_FPS, FRAME_DIRS, frame_folder, list_images

#: The image files an image folder source reads (a subset of what tracker.evaluation.datasets lists).
IMAGE_SUFFIXES = (".jpg", ".jpeg", ".png")


class Pacer:
    """Frame times: ``index / fps`` as fast as pulled, or waits for each frame's due time when realtime.

    In real time the first frame anchors the schedule and a frame's timestamp is the clock reading
    when it is handed out; a consumer that falls behind gets the next frame at once (nothing is
    skipped).
    """

    def __init__(self, fps: float, realtime: bool, clock: Callable[[], float] = time.monotonic,
                 sleep: Callable[[float], None] = time.sleep) -> None:
        if fps <= 0:
            raise ValueError(f"fps must be positive, got {fps}")
        self.fps = fps
        self.realtime = realtime
        self._clock = clock
        self._sleep = sleep
        self._start: float | None = None

    def stamp(self, index: int) -> float:
        """Wait if the frame is not due yet (real time only) and return its timestamp."""
        if not self.realtime:
            return index / self.fps
        now = self._clock()
        if self._start is None:
            self._start = now - index / self.fps
        due = self._start + index / self.fps
        if due > now:
            self._sleep(due - now)
            now = self._clock()
        return now


_END = object()  # the decoder thread's end-of-file marker


class FileSource(FrameSource):
    """A recorded sequence: nothing is ever dropped. A decoder thread reads up to ``PREFETCH``
    frames ahead (OpenCV releases the GIL while decoding), so decoding overlaps the consumer's
    work on another core; a decode error reaches ``read`` in order. Timestamps are paced at
    ``fps``, or ``ASSUMED_FPS`` when the file does not tell its rate."""

    PREFETCH = 8

    def __init__(self, description: str, first: np.ndarray, fps: float | None,
                 frame_count: int | None, realtime: bool, clock: Callable[[], float],
                 sleep: Callable[[float], None]) -> None:
        height, width = first.shape[:2]
        super().__init__(description, (width, height), fps, frame_count, is_live=False)
        self._pending: np.ndarray | None = first
        self._pacer = Pacer(fps or ASSUMED_FPS, realtime, clock, sleep)
        self._index = 0
        self._closed = False
        self._ended = False
        self._ahead: queue.Queue[object] = queue.Queue(maxsize=self.PREFETCH)
        self._stop = threading.Event()
        self._decoder = threading.Thread(target=self._decode_ahead, name="frame-decoder", daemon=True)
        self._decoder.start()

    def read(self) -> Frame | None:
        if self._closed or self._ended:
            return None
        if self._pending is not None:
            image, self._pending = self._pending, None
        else:
            item = self._ahead.get()
            if isinstance(item, SourceError):
                self._ended = True
                raise item
            if item is _END:
                self._ended = True
                return None
            image = item
        frame = Frame(image, self._pacer.stamp(self._index), self._index)
        self._index += 1
        return frame

    def close(self) -> None:
        """Stop the decoder thread (subclasses release their reader after this)."""
        self._closed = True
        self._pending = None
        self._stop.set()
        self._decoder.join()

    def _decode_ahead(self) -> None:
        index = 1
        while not self._stop.is_set():
            try:
                image = self._load(index)
            except SourceError as exc:
                self._hand_over(exc)
                return
            if image is None:
                self._hand_over(_END)
                return
            self._hand_over(image)
            index += 1

    def _hand_over(self, item: object) -> None:
        while not self._stop.is_set():
            try:
                self._ahead.put(item, timeout=0.05)
                return
            except queue.Full:
                continue

    @abstractmethod
    def _load(self, index: int) -> np.ndarray | None:
        """Image number ``index`` (never 0: that one was read at open), or ``None`` at the end;
        called from the decoder thread only."""


class VideoFileSource(FileSource):
    """A video file decoded by OpenCV's FFmpeg backend."""

    def __init__(self, path: Path, realtime: bool = False, fps: float | None = None,
                 clock: Callable[[], float] = time.monotonic,
                 sleep: Callable[[float], None] = time.sleep) -> None:
        if not path.is_file():
            raise SourceError(f"video file not found: {path}")
        # One decoder thread: on 2 cores the tracking loop needs the other core more than FFmpeg's
        # frame threading does (the loop ran faster so, docs/track.md).
        capture = cv2.VideoCapture(str(path), cv2.CAP_FFMPEG, [cv2.CAP_PROP_N_THREADS, 1])
        if not capture.isOpened():
            raise SourceError(f"cannot open {path}: not a video OpenCV can read")
        ok, first = capture.read()
        if not ok or first is None:
            capture.release()
            raise SourceError(f"no frame decodes from {path}: unsupported codec or corrupt file")
        count = int(capture.get(cv2.CAP_PROP_FRAME_COUNT))
        self._capture = capture
        super().__init__(str(path), first, fps or nominal_fps(capture), count if count > 0 else None,
                         realtime, clock, sleep)

    def _load(self, index: int) -> np.ndarray | None:
        ok, image = self._capture.read()
        return image if ok else None

    def close(self) -> None:
        super().close()
        self._capture.release()


class ImageFolderSource(FileSource):
    """A folder of .jpg/.png images in natural name order (``img2`` before ``img10``); a benchmark
    sequence's folder is read from its ``img/``, ``imgs/`` or ``color/``."""

    def __init__(self, path: Path, realtime: bool = False, fps: float | None = None,
                 clock: Callable[[], float] = time.monotonic,
                 sleep: Callable[[float], None] = time.sleep) -> None:
        files = [p for p in list_images(frame_folder(path)) if p.suffix.lower() in IMAGE_SUFFIXES]
        if not files:
            raise SourceError(f"no .jpg or .png images in folder {path} (nor in its {', '.join(FRAME_DIRS)})")
        self._files = files
        first = self._imread(files[0])
        self._shape = first.shape
        super().__init__(str(path), first, fps, len(files), realtime, clock, sleep)

    @staticmethod
    def _imread(path: Path) -> np.ndarray:
        image = cv2.imread(str(path), cv2.IMREAD_COLOR)
        if image is None:
            raise SourceError(f"cannot read image {path}")
        return image

    def _load(self, index: int) -> np.ndarray | None:
        if index >= len(self._files):
            return None
        image = self._imread(self._files[index])
        if image.shape != self._shape:  # the tracker, the camera model and the video assume one size
            raise SourceError(f"image {self._files[index]} is {image.shape[1]}x{image.shape[0]}, the folder's "
                              f"first is {self._shape[1]}x{self._shape[0]}: one sequence has one frame size")
        return image
