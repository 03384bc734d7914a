"""Progress for long runs: a bar for files of known length, a one-line status for live sources."""
from __future__ import annotations

import sys
import time
from collections.abc import Callable
from typing import TextIO


class ProgressReporter:
    """Redraws one stderr line at most ``interval`` seconds apart (new lines when not a TTY)."""

    def __init__(self, total: int | None, stream: TextIO | None = None, interval: float = 0.25,
                 enabled: bool = True) -> None:
        stream = stream or sys.stderr  # looked up now: sys.stderr may have been replaced since import
        self.total = total
        self.stream = stream
        self.interval = interval if stream.isatty() else max(interval, 2.0)
        self.enabled = enabled
        self._tty = stream.isatty()
        self._start = time.monotonic()
        self._last = self._start  # the first line waits an interval, so its fps means something
        self._drawn = False

    def update(self, done: int, status: str | Callable[[], str] = "", force: bool = False) -> None:
        """Redraw if due (or ``force``); a callable ``status`` is called only when the line is drawn."""
        now = time.monotonic()
        if not self.enabled or (not force and now - self._last < self.interval):
            return
        self._last = now
        if callable(status):
            status = status()
        fps = done / max(now - self._start, 1e-9)
        if self.total:
            share = min(done / self.total, 1.0)
            bar = "#" * round(share * 24)
            line = f"[{bar:<24}] {share:4.0%} {done}/{self.total} frames {fps:5.1f} fps {status}"
        else:
            line = f"{done} frames {fps:5.1f} fps {status}"
        if self._tty:
            self.stream.write("\r" + line[:150].ljust(150))
        else:
            self.stream.write(line + "\n")
        self.stream.flush()
        self._drawn = True

    def note(self, line: str) -> None:
        """A line of its own on the stream (a warning), written over the progress line on a TTY so
        that the next redraw comes below it; shown whether progress is enabled or not."""
        self.stream.write(("\r" + line.ljust(150) if self._tty and self._drawn else line) + "\n")
        self.stream.flush()

    def close(self) -> None:
        if self.enabled and self._drawn and self._tty:
            self.stream.write("\n")
            self.stream.flush()
