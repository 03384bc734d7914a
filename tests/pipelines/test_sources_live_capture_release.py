"""A live capture is released whichever way its source ends, even when the wait for its opening is
interrupted just as it opened (a camera must not stay held, busy for the next run, by a source that
failed to open); and a read that hands back no image is no frame."""
from __future__ import annotations

import threading

import numpy as np
import pytest

from pipelines.sources import SourceError
from pipelines.sources.live import LatestFrameGrabber, LiveSource, _Opening

WAIT = 10.0  # generous bound for thread hand-offs; never asserted on as a duration


class ScriptedCapture:
    """Hands out ``reads`` in order, then fails every read; records its release."""

    def __init__(self, reads: list[tuple[bool, np.ndarray | None]]) -> None:
        self._reads = list(reads)
        self.released = threading.Event()

    def read(self) -> tuple[bool, np.ndarray | None]:
        return self._reads.pop(0) if self._reads else (False, None)

    def release(self) -> None:
        self.released.set()


def test_a_live_source_that_never_delivers_releases_its_capture() -> None:
    capture = ScriptedCapture([])
    with pytest.raises(SourceError, match="no frame from silent camera within 0.1 s"):
        LiveSource(capture, "silent camera", open_timeout=0.1)
    assert capture.released.wait(WAIT)


def test_a_read_that_reports_success_without_an_image_is_no_frame() -> None:
    image = np.full((4, 6, 3), 7, np.uint8)
    capture = ScriptedCapture([(True, None), (True, image)])
    grabber = LatestFrameGrabber(capture)
    grabber.start()
    try:
        frame = grabber.get(WAIT)
        assert frame is not None and frame.image is image and frame.index == 0
        assert grabber.grabbed == 1 and grabber.dropped == 0
    finally:
        grabber.stop()
    assert capture.released.wait(WAIT)


class _InterruptedAfterTheOpen(threading.Event):
    """An event whose wait is cut short by a signal's exception just as the capture has opened."""

    def wait(self, timeout: float | None = None) -> bool:
        super().wait(timeout)
        raise KeyboardInterrupt


def test_a_capture_that_opened_as_the_wait_was_interrupted_is_released() -> None:
    capture = ScriptedCapture([])
    opening = _Opening(lambda: capture)
    opening._done = _InterruptedAfterTheOpen()
    opening.run()  # opened before anyone gave up on it
    with pytest.raises(KeyboardInterrupt):
        opening.wait()
    assert capture.released.is_set()
