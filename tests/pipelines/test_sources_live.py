"""Live sources: the newest-frame grabber, stalls, open failures and a real UDP stream via FFmpeg."""
from __future__ import annotations

import itertools
import os
import signal
import socket
import subprocess
import threading
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from pipelines.sources import SourceError, open_source
from pipelines.sources.live import LatestFrameGrabber, LiveSource, _Opening, open_interruptibly
from tests.support import free_udp_port, require_ffmpeg


WAIT = 10.0  # generous bound for thread hand-offs; tests never assert on durations


class BurstCapture:
    """A fake capture that delivers bursts of frames back to back, then blocks until the next burst
    is released; after the last burst every read fails (a dead stream)."""

    def __init__(self, bursts: list[int]) -> None:
        self._bursts = list(bursts)
        self._served = 0
        self.burst_done = threading.Event()
        self._gate = threading.Event()
        self.released = threading.Event()

    def read(self) -> tuple[bool, np.ndarray | None]:
        if not self._bursts:
            return False, None
        if self._bursts[0] == 0:
            self._bursts.pop(0)
            self.burst_done.set()
            self._gate.wait()
            self._gate.clear()
            return self.read()
        self._bursts[0] -= 1
        self._served += 1
        return True, np.full((4, 6, 3), self._served - 1, np.uint8)

    def next_burst(self) -> None:
        self.burst_done.clear()
        self._gate.set()

    def release(self) -> None:
        self.released.set()


def counter_clock() -> Callable[[], float]:
    ticks = itertools.count(1000)
    return lambda: float(next(ticks))


def test_grabber_hands_out_the_newest_frame_and_counts_drops() -> None:
    capture = BurstCapture([5, 3])
    grabber = LatestFrameGrabber(capture, clock=counter_clock())
    grabber.start()
    try:
        assert capture.burst_done.wait(WAIT)
        frame = grabber.get(0.0)
        assert frame is not None
        assert (frame.index, int(frame.image[0, 0, 0]), frame.timestamp) == (4, 4, 1004.0)
        assert grabber.dropped == 4 and grabber.grabbed == 5
        assert grabber.get(0.0) is None  # nothing newer than what was handed out
        capture.next_burst()
        assert capture.burst_done.wait(WAIT)
        frame = grabber.get(0.0)
        assert frame is not None and frame.index == 7
        assert grabber.dropped == 6
    finally:
        capture.next_burst()
        grabber.stop()
    assert capture.released.wait(WAIT)


def test_grabber_failure_reaches_the_consumer() -> None:
    class Broken:
        def read(self) -> tuple[bool, np.ndarray | None]:
            raise RuntimeError("device unplugged")

        def release(self) -> None:
            pass

    grabber = LatestFrameGrabber(Broken())
    grabber.start()
    with pytest.raises(SourceError, match="device unplugged"):
        grabber.get(WAIT)
    grabber.stop()


def test_live_source_raises_stream_stalled_when_frames_stop() -> None:
    capture = BurstCapture([3])
    source = LiveSource(capture, "fake stream", stall_timeout=0.2, open_timeout=WAIT)
    with source:
        assert source.is_live and source.size == (6, 4) and source.frame_count is None
        assert capture.burst_done.wait(WAIT)
        first = source.read()
        assert first is not None and first.index == 2  # the newest of the burst
        assert source.dropped == 2
        capture.next_burst()  # the stream dies: every read fails from now on
        with pytest.raises(SourceError, match="stream stalled: no frame from fake stream for 0.2 s"):
            source.read()
    assert capture.released.wait(WAIT)
    assert source.read() is None


def test_live_source_that_never_delivers_does_not_open() -> None:
    with pytest.raises(SourceError, match="no frame from silent within 0.1 s"):
        LiveSource(BurstCapture([]), "silent", open_timeout=0.1)


def test_camera_that_does_not_open() -> None:
    with pytest.raises(SourceError, match="camera 97 does not open"):
        open_source("97")


@pytest.mark.parametrize("spec", ["99999999999", "100", "\u00b2"])  # once tracebacks from OpenCV or int()
def test_camera_indexes_opencv_cannot_take_are_one_line_errors(spec: str) -> None:
    with pytest.raises(SourceError, match="out of range|no such video file"):
        open_source(spec)


class _Stop(Exception):
    pass


class _SlowToOpen:
    """A capture whose opening blocks until ``finish`` is set, like OpenCV's on a silent stream."""

    def __init__(self) -> None:
        self.finish = threading.Event()
        self.released = threading.Event()

    def open(self) -> "_SlowToOpen":
        self.finish.wait(WAIT)
        return self

    def release(self) -> None:
        self.released.set()


def test_a_signal_ends_the_wait_for_a_capture_that_is_still_opening() -> None:
    """OpenCV's blocking open on the main thread once held off Ctrl-C for the whole open timeout."""
    def stop(signum: int, frame: object) -> None:
        raise _Stop

    capture = _SlowToOpen()
    previous = signal.signal(signal.SIGUSR1, stop)
    timer = threading.Timer(0.1, os.kill, (os.getpid(), signal.SIGUSR1))
    try:
        timer.start()
        with pytest.raises(_Stop):
            open_interruptibly(capture.open)
    finally:
        timer.cancel()
        signal.signal(signal.SIGUSR1, previous)
    assert not capture.released.is_set()
    capture.finish.set()  # it opens after all: nobody wants it any more
    assert capture.released.wait(WAIT)


def test_an_opened_capture_and_an_opening_error_reach_the_caller() -> None:
    capture = _SlowToOpen()
    capture.finish.set()
    assert open_interruptibly(capture.open) is capture and not capture.released.is_set()
    with pytest.raises(ZeroDivisionError):
        open_interruptibly(lambda: 1 // 0)


def test_refused_stream_is_not_called_a_timeout() -> None:
    with socket.socket() as closed:  # a port nothing listens on once this is closed
        closed.bind(("127.0.0.1", 0))
        port = closed.getsockname()[1]
    for url in (f"rtsp://127.0.0.1:{port}/live", f"http://127.0.0.1:{port}/live.mjpg"):
        with pytest.raises(SourceError) as error:
            open_source(url, open_timeout=WAIT)
        assert str(error.value) == (f"cannot open stream {url} (connection refused, not found, or not a "
                                    "stream FFmpeg can read)")


def test_silent_stream_is_a_timeout() -> None:
    with socket.socket() as server:  # accepts connections and never says a word
        server.bind(("127.0.0.1", 0))
        server.listen()
        url = f"rtsp://127.0.0.1:{server.getsockname()[1]}/live"
        with pytest.raises(SourceError, match=f"^cannot open stream {url}: nothing received within 0.5 s$"):
            open_source(url, open_timeout=0.5)


@pytest.fixture
def ffmpeg() -> str:
    return require_ffmpeg("a live UDP stream")


@pytest.mark.slow
def test_udp_stream_is_read_live_and_stalls_when_the_sender_stops(
        ffmpeg: str, tmp_path: Path, write_video: Callable[..., Path]) -> None:
    clip = write_video(tmp_path / "clip.mp4", 150, fps=30.0, size=(160, 120))
    url = f"udp://127.0.0.1:{free_udp_port()}"
    sender = subprocess.Popen(
        [ffmpeg, "-hide_banner", "-loglevel", "error", "-re", "-i", str(clip), "-c:v", "mpeg2video",
         "-g", "10", "-q:v", "4", "-f", "mpegts", f"{url}?pkt_size=1316"],
        stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    try:
        with open_source(url, stall_timeout=1.0, open_timeout=WAIT) as source:
            assert source.is_live and source.size == (160, 120)
            frames = [source.read() for _ in range(20)]
            sender.terminate()
            sender.wait(WAIT)
            with pytest.raises(SourceError, match="stream stalled"):
                while True:
                    source.read()
    finally:
        if sender.poll() is None:
            sender.kill()
            sender.wait()
    indexes = [f.index for f in frames]
    stamps = [f.timestamp for f in frames]
    assert indexes == sorted(set(indexes))
    assert stamps == sorted(stamps) and stamps[0] < stamps[-1]
    assert all(f.image.shape == (120, 160, 3) for f in frames)


# A live capture is released whichever way its source ends, even when the wait for its opening is
# interrupted just as it opened (a camera must not stay held, busy for the next run, by a source that
# failed to open); and a read that hands back no image is no frame.


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


# A live source's first read: the frame that opened it is handed out only if nothing newer came
# meanwhile; a newer one replaces it, and the opening frame counts as dropped.


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
