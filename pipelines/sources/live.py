"""Live sources (a camera or a network stream): a grabber thread keeps only the newest frame."""
from __future__ import annotations

import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Protocol

import cv2
import numpy as np

from pipelines.sources.base import Frame, FrameSource, SourceError, nominal_fps

DEFAULT_STALL_TIMEOUT = 2.0
DEFAULT_OPEN_TIMEOUT = 10.0
MAX_CAMERA_INDEX = 100
#: A live source silent this long while it opens gets a note: opening and the first frame may
#: take up to ``open_timeout`` each, 10 to 20 s of a silent terminal.
WAIT_NOTICE_S = 2.0

#: Told a live source's description once it has been silent for ``WAIT_NOTICE_S`` while opening.
Waiting = Callable[[str], None]


class Capture(Protocol):
    """The part of ``cv2.VideoCapture`` the grabber uses."""

    def read(self) -> tuple[bool, np.ndarray | None]: ...

    def release(self) -> None: ...


class LatestFrameGrabber:
    """Reads a capture on a daemon thread and holds only the newest frame.

    A frame replaced before anyone took it counts as dropped. Frame indexes are the grab
    counter, so a gap between two handed-out indexes is the number of frames dropped between them.
    The capture is released by the grabber thread itself, never while a read is in progress.
    """

    def __init__(self, capture: Capture, clock: Callable[[], float] = time.monotonic,
                 name: str = "frame-grabber") -> None:
        self._capture = capture
        self._clock = clock
        self._cond = threading.Condition()
        self._latest: Frame | None = None
        self._grabbed = 0
        self._dropped = 0
        self._error: BaseException | None = None
        self._stopping = threading.Event()
        self._thread = threading.Thread(target=self._run, name=name, daemon=True)

    @property
    def dropped(self) -> int:
        with self._cond:
            return self._dropped

    @property
    def grabbed(self) -> int:
        with self._cond:
            return self._grabbed

    def start(self) -> None:
        self._thread.start()

    def _run(self) -> None:
        try:
            while not self._stopping.is_set():
                ok, image = self._capture.read()
                stamp = self._clock()
                if not ok or image is None:
                    # A failed read may be a glitch; the consumer's stall timeout decides when to give up.
                    self._stopping.wait(0.005)
                    continue
                with self._cond:
                    if self._latest is not None:
                        self._dropped += 1
                    self._latest = Frame(image, stamp, self._grabbed)
                    self._grabbed += 1
                    self._cond.notify_all()
        except Exception as exc:  # noqa: BLE001 - handed to the consumer as a SourceError
            with self._cond:
                self._error = exc
                self._cond.notify_all()
        finally:
            self._capture.release()

    def get(self, timeout: float) -> Frame | None:
        """The newest frame not handed out yet, waiting up to ``timeout`` s; ``None`` if none came."""
        with self._cond:
            self._cond.wait_for(lambda: self._latest is not None or self._error is not None, timeout)
            if self._error is not None:
                raise SourceError(f"frame grabber failed: {self._error}")
            frame, self._latest = self._latest, None
            return frame

    def stop(self, join_timeout: float = 1.0) -> None:
        """Ask the thread to finish and wait briefly (a read blocked in the driver may outlive this)."""
        self._stopping.set()
        if self._thread.is_alive() and threading.current_thread() is not self._thread:
            self._thread.join(join_timeout)


class LiveSource(FrameSource):
    """A camera or stream read by a ``LatestFrameGrabber``; timestamps are grab times on ``clock``."""

    def __init__(self, capture: Capture, description: str, fps: float | None = None,
                 stall_timeout: float = DEFAULT_STALL_TIMEOUT,
                 open_timeout: float = DEFAULT_OPEN_TIMEOUT,
                 clock: Callable[[], float] = time.monotonic) -> None:
        self._grabber = LatestFrameGrabber(capture, clock, name=f"grabber {description}")
        self._stall_timeout = stall_timeout
        self._closed = False
        self._grabber.start()
        first = self._grabber.get(open_timeout)
        if first is None:
            self._grabber.stop()
            raise SourceError(f"no frame from {description} within {open_timeout:g} s")
        self._pending: Frame | None = first
        self._skipped = 0
        height, width = first.image.shape[:2]
        super().__init__(description, (width, height), fps, None, is_live=True)

    @property
    def dropped(self) -> int:
        return self._grabber.dropped + self._skipped

    def read(self) -> Frame | None:
        if self._closed:
            return None
        if self._pending is not None:
            frame, self._pending = self._pending, None
            newer = self._grabber.get(0.0)
            if newer is None:
                return frame
            self._skipped += 1
            return newer
        frame = self._grabber.get(self._stall_timeout)
        if frame is None:
            raise SourceError(f"stream stalled: no frame from {self.description} "
                              f"for {self._stall_timeout:g} s")
        return frame

    def close(self) -> None:
        if not self._closed:
            self._closed = True
            self._grabber.stop()


class _Opening:
    """A capture being opened on a helper thread; released there if nobody waits for it any more."""

    def __init__(self, open_capture: Callable[[], cv2.VideoCapture]) -> None:
        self._open_capture = open_capture
        self._lock = threading.Lock()
        self._done = threading.Event()
        self._capture: cv2.VideoCapture | None = None
        self._error: BaseException | None = None
        self._abandoned = False

    def run(self) -> None:
        try:
            capture = self._open_capture()
        except BaseException as exc:  # handed to the waiter (cv2.error, a bad argument...)
            capture, self._error = None, exc
        with self._lock:
            self._capture = capture
            abandoned = self._abandoned
        self._done.set()
        if abandoned and capture is not None:
            capture.release()

    def wait(self) -> cv2.VideoCapture:
        try:
            self._done.wait()
        except BaseException:
            with self._lock:
                self._abandoned = True
                capture = self._capture
            if capture is not None:
                capture.release()
            raise
        if self._error is not None:
            raise self._error
        assert self._capture is not None
        return self._capture


def open_interruptibly(open_capture: Callable[[], cv2.VideoCapture]) -> cv2.VideoCapture:
    """``open_capture()`` on a helper thread, waited for here: OpenCV blocks while it opens (up to
    its open timeout for a stream), and on the main thread that would hold off a Ctrl-C or SIGTERM
    until it returned. A wait cut short by a signal's exception leaves the capture to be released
    as soon as it opens."""
    opening = _Opening(open_capture)
    threading.Thread(target=opening.run, name="capture-open", daemon=True).start()
    return opening.wait()


@contextmanager
def _told_while_silent(description: str, waiting: Waiting | None) -> Iterator[None]:
    """Call ``waiting(description)`` once if the block is still running after ``WAIT_NOTICE_S``."""
    if waiting is None:
        yield
        return
    timer = threading.Timer(WAIT_NOTICE_S, waiting, args=(description,))
    timer.daemon = True
    timer.start()
    try:
        yield
    finally:
        timer.cancel()


def open_camera(index: int, stall_timeout: float = DEFAULT_STALL_TIMEOUT,
                open_timeout: float = DEFAULT_OPEN_TIMEOUT, waiting: Waiting | None = None) -> LiveSource:
    """Camera number ``index`` (0 to 99) through OpenCV's default backend."""
    if not 0 <= index < MAX_CAMERA_INDEX:  # OpenCV reads the hundreds of an index as a backend's number
        raise SourceError(f"camera index {index} is out of range (0 to {MAX_CAMERA_INDEX - 1})")
    with _told_while_silent(f"camera {index}", waiting):
        capture = open_interruptibly(lambda: cv2.VideoCapture(index))
        if not capture.isOpened():
            raise SourceError(f"camera {index} does not open (not connected, busy or no permission)")
        return LiveSource(capture, f"camera {index}", nominal_fps(capture), stall_timeout, open_timeout)


def open_stream(url: str, stall_timeout: float = DEFAULT_STALL_TIMEOUT,
                open_timeout: float = DEFAULT_OPEN_TIMEOUT, waiting: Waiting | None = None) -> LiveSource:
    """A network stream read by OpenCV's FFmpeg backend (udp://, rtsp://, http(s)://, ...)."""
    params = [cv2.CAP_PROP_OPEN_TIMEOUT_MSEC, int(open_timeout * 1000),
              cv2.CAP_PROP_READ_TIMEOUT_MSEC, int(stall_timeout * 1000)]
    started = time.monotonic()
    with _told_while_silent(url, waiting):
        capture = open_interruptibly(lambda: cv2.VideoCapture(url, cv2.CAP_FFMPEG, params))
        if not capture.isOpened():
            if time.monotonic() - started >= open_timeout:
                raise SourceError(f"cannot open stream {url}: nothing received within {open_timeout:g} s")
            raise SourceError(f"cannot open stream {url} (connection refused, not found, or not a stream "
                              "FFmpeg can read)")
        return LiveSource(capture, url, nominal_fps(capture), stall_timeout, open_timeout)
