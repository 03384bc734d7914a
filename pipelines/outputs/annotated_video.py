"""The annotated video: each frame with the subject box, its centre, the error vector and the rates."""
from __future__ import annotations

import os
import queue
import threading
from collections.abc import Sequence
from pathlib import Path
from types import TracebackType

import cv2
import numpy as np

from tracker.runtime.estimate import TargetEstimate, TrackState

#: Container suffix -> FourCC, both FFmpeg's MPEG-4 part 2 encoder (about twice as fast as Motion JPEG
#: at 720p, files several times smaller). An .mp4 is finalised by ``close()``; an .avi stays readable up
#: to the last frames that reached the disk even if the process is killed.
CODECS = {".mp4": "mp4v", ".avi": "XVID"}
STATE_COLOURS = {  # BGR
    TrackState.TRACKING: (0, 200, 0),
    TrackState.SEARCHING: (0, 200, 255),
    TrackState.LOST: (0, 0, 255),
}
_FONT = cv2.FONT_HERSHEY_SIMPLEX


def _put_lines(image: np.ndarray, lines: Sequence[str]) -> None:
    y = 8
    for line in lines:
        (w, h), base = cv2.getTextSize(line, _FONT, 0.5, 1)
        cv2.rectangle(image, (4, y - 2), (12 + w, y + h + base), (0, 0, 0), cv2.FILLED)
        # plain 8-connected strokes: anti-aliased text took half of ``annotate``'s time
        cv2.putText(image, line, (8, y + h), _FONT, 0.5, (255, 255, 255), 1, cv2.LINE_8)
        y += h + base + 6


def annotate(image: np.ndarray, estimate: TargetEstimate | None = None,
             rates_dps: tuple[float, float] | None = None, lines: Sequence[str] = (),
             scale: float = 1.0, copy: bool = True) -> np.ndarray:
    """A copy of ``image`` with the image centre, and if given the box coloured by state, the subject
    centre cross, the error vector from image centre to subject centre, the state, confidence and
    commanded yaw/pitch rates (°/s), then any extra text ``lines``. ``scale``: image pixels per
    pixel of the estimate's frame (for an image shrunk from that frame). ``copy=False`` draws on
    ``image`` itself (for a caller that owns it) and returns it."""
    out = image.copy() if copy else image
    height, width = out.shape[:2]
    centre = (width // 2, height // 2)
    cv2.drawMarker(out, centre, (200, 200, 200), cv2.MARKER_CROSS, 20, 1)
    text = []
    if estimate is not None:
        colour = STATE_COLOURS[estimate.state]
        subject = tuple(round(v * scale) for v in estimate.center)
        cv2.arrowedLine(out, centre, subject, (255, 255, 0), 2, cv2.LINE_AA, tipLength=0.08)
        x, y, w, h = (round(v * scale) for v in estimate.box)
        cv2.rectangle(out, (x, y), (x + w, y + h), colour, 2)
        cv2.drawMarker(out, subject, colour, cv2.MARKER_CROSS, 16, 2)
        text.append(f"#{estimate.frame_index} t={estimate.timestamp:.3f}s "
                    f"{estimate.state.value} conf={estimate.confidence:.2f}")
    if rates_dps is not None:
        text.append(rates_text(rates_dps))
    _put_lines(out, [*text, *lines])
    return out


def rates_text(rates_dps: tuple[float, float]) -> str:
    """The commanded rates as the video shows them: ``yaw +12.3 pitch -4.0 deg/s``."""
    return f"yaw {rates_dps[0]:+.1f} pitch {rates_dps[1]:+.1f} deg/s"


def video_size(size: tuple[int, int], max_width: int | None) -> tuple[int, int]:
    """The written size for frames of ``size``: shrunk to at most ``max_width`` pixels wide (same
    aspect ratio, even sides as the encoder needs), or ``size`` itself when it fits or when
    ``max_width`` is None."""
    width, height = size
    if max_width is None or width <= max_width:
        return size
    scale = max_width / width
    return max(2, round(width * scale / 2) * 2), max(2, round(height * scale / 2) * 2)


class AnnotatedVideoWriter:
    """Writes annotated frames as they come (.mp4 or .avi, MPEG-4 part 2); ``close()`` finalises.

    ``size`` is the frames' size; with ``max_width`` wider frames are shrunk before drawing, so the
    file is ``video_size(size, max_width)`` (encoding is most of the cost: a 1280x720 frame takes
    3.6-5 ms of CPU, the same frame at 640x360 under 2 ms including the shrinking).
    """

    def __init__(self, path: str | os.PathLike[str], size: tuple[int, int], fps: float,
                 max_width: int | None = None) -> None:
        self.path = Path(path)
        codec = CODECS.get(self.path.suffix.lower())
        if codec is None:
            raise ValueError(f"annotated video must end in {' or '.join(CODECS)}: {self.path}")
        if max_width is not None and max_width < 2:
            raise ValueError(f"max_width must be at least 2 pixels, got {max_width}")
        self.size = size
        self.video_size = video_size(size, max_width)
        self._scale = self.video_size[0] / size[0]
        self._writer = cv2.VideoWriter(str(self.path), cv2.CAP_FFMPEG, cv2.VideoWriter_fourcc(*codec),
                                       fps, self.video_size)
        if not self._writer.isOpened():
            raise OSError(f"cannot write video {self.path}")
        self.frames = 0

    def write(self, image: np.ndarray, estimate: TargetEstimate | None = None,
              rates_dps: tuple[float, float] | None = None, lines: Sequence[str] = ()) -> None:
        """Annotate ``image`` (see ``annotate``) and append it; the size must match the writer's."""
        height, width = image.shape[:2]
        if (width, height) != self.size:
            raise ValueError(f"frame is {width}x{height}, video is {self.size[0]}x{self.size[1]}")
        shrink = self.video_size != self.size
        if shrink:  # a new array of our own, so it is drawn on as it is
            image = cv2.resize(image, self.video_size, interpolation=cv2.INTER_AREA)
        self._writer.write(annotate(image, estimate, rates_dps, lines, self._scale, copy=not shrink))
        self.frames += 1

    def close(self) -> None:
        self._writer.release()

    def __enter__(self) -> AnnotatedVideoWriter:
        return self

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        self.close()


class BackgroundVideoWriter:
    """An ``AnnotatedVideoWriter`` fed through a bounded queue and drained by its own thread, so
    drawing and encoding (OpenCV releases the GIL) overlap the tracking loop. ``write`` blocks
    when ``queue_size`` frames are waiting, so no frame is dropped; a failure in the worker is
    raised by the next ``write`` or by ``close``."""

    def __init__(self, path: str | os.PathLike[str], size: tuple[int, int], fps: float,
                 max_width: int | None = None, queue_size: int = 32) -> None:
        self._writer = AnnotatedVideoWriter(path, size, fps, max_width)
        self.path = self._writer.path
        self.video_size = self._writer.video_size
        self._queue: queue.Queue[tuple | None] = queue.Queue(maxsize=queue_size)
        self._error: BaseException | None = None
        self._reported = False
        self._thread = threading.Thread(target=self._drain, name="annotated-video", daemon=True)
        self._thread.start()

    @property
    def frames(self) -> int:
        return self._writer.frames

    def write(self, image: np.ndarray, estimate: TargetEstimate | None = None,
              rates_dps: tuple[float, float] | None = None, lines: Sequence[str] = ()) -> None:
        self._raise_error()
        self._queue.put((image, estimate, rates_dps, tuple(lines)))

    def close(self) -> None:
        """Write what is queued, then finalise the file."""
        if self._thread.is_alive():
            self._queue.put(None)
            self._thread.join()
        self._writer.close()
        self._raise_error()

    def _drain(self) -> None:
        while (item := self._queue.get()) is not None:
            if self._error is None:
                try:
                    self._writer.write(*item)
                except BaseException as exc:  # kept for the caller's thread
                    self._error = exc

    def _raise_error(self) -> None:
        """Raise the worker's failure, once; the worker keeps draining (and dropping) after it."""
        if self._error is not None and not self._reported:
            self._reported = True
            raise self._error

    def __enter__(self) -> BackgroundVideoWriter:
        return self

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        self.close()
