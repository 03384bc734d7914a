"""A live source's first read: the frame that opened it is handed out only if nothing newer came
meanwhile; a newer one replaces it, and the opening frame counts as dropped."""
from __future__ import annotations

import threading

import numpy as np

from pipelines.sources.live import LiveSource

WAIT = 10.0  # generous bound for thread hand-offs; never asserted on as a duration


class GatedCapture:
    """One frame, then ``later`` more once ``go`` is set; after those, reads block until ``done``
    is set and then fail (a stream with nothing more to say)."""

    def __init__(self, later: int) -> None:
        self.go = threading.Event()
        self.delivered = threading.Event()
        self.done = threading.Event()
        self._later = later
        self._served = 0

    def read(self) -> tuple[bool, np.ndarray | None]:
        if self._served > self._later:
            self.delivered.set()
            self.done.wait(WAIT)
            return False, None
        if self._served == 1:
            self.go.wait(WAIT)
        self._served += 1
        return True, np.full((4, 6, 3), self._served - 1, np.uint8)

    def release(self) -> None:
        pass


def test_a_newer_frame_replaces_the_one_the_source_opened_with() -> None:
    capture = GatedCapture(later=2)
    with LiveSource(capture, "gated", stall_timeout=WAIT, open_timeout=WAIT) as source:
        capture.go.set()
        assert capture.delivered.wait(WAIT)
        frame = source.read()
        assert frame is not None and frame.index == 2 and int(frame.image[0, 0, 0]) == 2
        assert source.dropped == 2  # frame 1 in the grabber, frame 0 at this read
        capture.done.set()


def test_the_opening_frame_is_handed_out_when_nothing_newer_came() -> None:
    capture = GatedCapture(later=0)
    with LiveSource(capture, "gated", stall_timeout=WAIT, open_timeout=WAIT) as source:
        frame = source.read()
        assert frame is not None and frame.index == 0 and source.dropped == 0
        capture.done.set()
