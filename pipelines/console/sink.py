"""The console's sink: keeps the loop's newest frame and record, and encodes JPEGs for viewers
on a thread of its own. ``on_frame`` only swaps a reference, so a viewer never slows the loop."""
from __future__ import annotations

import threading
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from typing import Any

import cv2
import numpy as np

from pipelines.console.operator import ConsoleView
from pipelines.console.overlay import draw, shrunk

JPEG_QUALITY = 80
#: Colour at half resolution both ways (4:2:0), as cameras and browsers expect: it encodes in about
#: 85 % of the time of OpenCV's default here, CPU taken from a loop running at file speed.
CHROMA_HALVED = (cv2.IMWRITE_JPEG_SAMPLING_FACTOR, cv2.IMWRITE_JPEG_SAMPLING_FACTOR_420)


class ConsoleFailed(OSError):
    """The console's server stopped: the run ends like on any other output's failure (the
    gimbal is stopped and released)."""


@dataclass(frozen=True)
class Snapshot:
    seq: int  # 1 for the first frame handed over, then one more per frame
    view: ConsoleView
    image: np.ndarray  # the loop's frame, never drawn on


class ConsoleSink:
    """``on_frame(record, frame)`` from the loop's thread; ``latest()``, ``encode()`` and
    ``wake_on_next`` from the server's. ``describe`` turns the loop's record into a
    ``ConsoleView`` (a few attribute reads: it runs on the loop's thread); ``dead_zone_px`` gives
    the dead zone's half-width in source pixels as it stands (settings change it)."""

    name = "console"

    def __init__(self, describe: Callable[[Any], ConsoleView] = lambda view: view,
                 dead_zone_px: Callable[[], float] = lambda: 0.0, quality: int = JPEG_QUALITY) -> None:
        self._describe = describe
        self._dead_zone_px = dead_zone_px
        self._quality = quality
        self._lock = threading.Lock()
        self._latest: Snapshot | None = None
        self._cache: dict[tuple[int, int], bytes] = {}  # (seq, width) of the newest frame only
        self._wake: Callable[[], None] | None = None
        self._encoder = ThreadPoolExecutor(max_workers=1, thread_name_prefix="console-jpeg")
        self.failure: BaseException | None = None

    # -- the loop's side --------------------------------------------------------------------
    def on_frame(self, record: Any, frame: Any) -> None:
        """Keep ``frame`` (a ``Frame`` or an image; not copied: the loop never draws on its frames)
        as the newest; wake a viewer waiting for it. Raises ``ConsoleFailed`` once the server
        has died, so the run stops the gimbal."""
        if self.failure is not None:
            reason = str(self.failure) or type(self.failure).__name__
            raise ConsoleFailed(f"the console stopped: {reason}") from self.failure
        image = getattr(frame, "image", frame)
        view = self._describe(record)
        with self._lock:
            seq = 1 if self._latest is None else self._latest.seq + 1
            self._latest = Snapshot(seq, view, image)
            wake, self._wake = self._wake, None
        if wake is not None:
            wake()

    def close(self) -> None:
        self._encoder.shutdown(wait=False, cancel_futures=True)

    # -- the server's side ------------------------------------------------------------------
    def latest(self) -> Snapshot | None:
        return self._latest

    def wake_on_next(self, wake: Callable[[], None], after_seq: int) -> bool:
        """Call ``wake`` (from the loop's thread) when a frame newer than ``after_seq`` arrives;
        False, and no call, when one is already there."""
        with self._lock:
            if self._latest is not None and self._latest.seq > after_seq:
                return False
            self._wake = wake
            return True

    def fail(self, error: BaseException) -> None:
        """The server died: the loop's next ``on_frame`` raises."""
        self.failure = error

    @property
    def executor(self) -> ThreadPoolExecutor:
        return self._encoder

    def encode(self, snapshot: Snapshot, width: int) -> bytes:
        """The snapshot drawn and encoded at most ``width`` pixels wide (run on ``executor``;
        each (frame, width) is encoded once for all the viewers asking for it)."""
        key = (snapshot.seq, width)
        cached = self._cache.get(key)
        if cached is not None:
            return cached
        image, scale = shrunk(snapshot.image, width)
        draw(image, snapshot.view, scale, self._dead_zone_px())
        ok, data = cv2.imencode(".jpg", image, [cv2.IMWRITE_JPEG_QUALITY, self._quality, *CHROMA_HALVED])
        if not ok:
            raise ValueError("JPEG encoding failed")
        jpeg = data.tobytes()
        self._cache = {k: v for k, v in self._cache.items() if k[0] == snapshot.seq}
        self._cache[key] = jpeg
        return jpeg
