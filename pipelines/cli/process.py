"""The process around a ``gimbaltrack`` run: Ctrl-C and the terminating signals held while the
modules load, standard streams closed by the caller (``>&-``, ``2>&-``), a stdout that went away,
and OpenCV's own chatter. Imports only what Python has loaded before any of our code runs, so
``pipelines.cli.main`` can use it before it holds the signals."""
from __future__ import annotations

import _signal
import errno
import io
import os
import sys
from collections.abc import Iterable

#: ``gimbal.signals``'s SIGINT and ``TERMINATING_SIGNALS``.
HELD_SIGNALS = tuple(getattr(_signal, name) for name in ("SIGINT", "SIGTERM", "SIGHUP", "SIGQUIT")
                     if hasattr(_signal, name))
STDOUT_FD, STDERR_FD = 1, 2


def hold_signals() -> Iterable[int] | None:
    """Block ``HELD_SIGNALS`` (they wait, queued, instead of interrupting an import); the mask to
    go back to, or None where the platform cannot block signals."""
    if not hasattr(_signal, "pthread_sigmask"):
        return None
    return _signal.pthread_sigmask(_signal.SIG_BLOCK, HELD_SIGNALS)


def release_signals(mask: Iterable[int] | None) -> None:
    """Go back to ``mask`` (from ``hold_signals``): what arrived meanwhile is delivered now."""
    if mask is not None:
        _signal.pthread_sigmask(_signal.SIG_SETMASK, mask)


def hold_on_devnull(fd: int) -> None:
    """Open /dev/null on ``fd``: one closed when the program started, so that no output file opened
    later takes that number (and gets what is written to stdout or stderr, OpenCV's own included),
    or one whose writes failed, so that nothing written later fails again."""
    null = os.open(os.devnull, os.O_WRONLY)
    if null != fd:
        os.dup2(null, fd)
        os.close(null)


def quiet_opencv(argv: list[str]) -> None:
    """Keep OpenCV's and FFmpeg's own warnings (``[ WARN:0@1.7] ...``, ``moov atom not found``) off
    the terminal, where they bury the one-line error that explains them, unless ``--debug`` is
    given or the variables are set already. Effective only before cv2 is imported."""
    if "--debug" not in argv:
        os.environ.setdefault("OPENCV_LOG_LEVEL", "ERROR")
        os.environ.setdefault("OPENCV_FFMPEG_LOGLEVEL", "8")  # AV_LOG_FATAL


def closed_stderr() -> io.TextIOBase:
    """``sys.stderr`` when fd 2 was closed (``2>&-``), where Python gives None and ``print(...,
    file=sys.stderr)`` writes to stdout: the user chose not to see the errors, so they go to
    /dev/null, never among the results; the exit status still tells a failure."""
    hold_on_devnull(STDERR_FD)
    return open(STDERR_FD, "w", closefd=False)


class ClosedStdout(io.TextIOBase):
    """``sys.stdout`` when fd 1 was closed (``>&-``). It holds fd 1 open on /dev/null, so that no
    output file opened later takes that number, and flushing what was written raises EBADF: a
    closed stdout is reported like a full disk's (one line, exit 1), and a run's files are kept."""

    def __init__(self) -> None:
        super().__init__()
        hold_on_devnull(STDOUT_FD)
        self._written = False

    def writable(self) -> bool:
        return True

    def fileno(self) -> int:
        return STDOUT_FD

    def write(self, text: str) -> int:
        self._written = self._written or bool(text)
        return len(text)

    def flush(self) -> None:
        if self._written:  # said once: the flush at exit finds nothing more
            self._written = False
            raise OSError(errno.EBADF, "stdout is closed: the results went nowhere")


def standard_streams() -> None:
    """Replace a stdout or stderr the caller closed (see ``ClosedStdout``, ``closed_stderr``)."""
    if sys.stderr is None:  # fd 2 closed (2>&-): print(file=None) wrote the errors among the results
        sys.stderr = closed_stderr()
    if sys.stdout is None:  # fd 1 closed (>&-): Python gives no stdout, and print() drops the results
        sys.stdout = ClosedStdout()


def drop_stdout() -> None:
    """Point stdout at /dev/null, so that Python's own flush at exit cannot fail a second time."""
    hold_on_devnull(sys.stdout.fileno())
