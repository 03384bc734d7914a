"""Frame sources: ``open_source(spec)`` for a video file, an image folder, a camera or a stream URL."""
from __future__ import annotations

import os
import re
import time
from collections.abc import Callable
from pathlib import Path

from pipelines.sources.base import Frame, FrameSource, SourceError
from pipelines.sources.files import ImageFolderSource, VideoFileSource
from pipelines.sources.live import DEFAULT_OPEN_TIMEOUT, DEFAULT_STALL_TIMEOUT, Waiting, open_camera, open_stream

__all__ = ["Frame", "FrameSource", "SourceError", "open_source"]

_URL = re.compile(r"^[a-z][a-z0-9+.-]*://", re.IGNORECASE)


def open_source(spec: str | os.PathLike[str] | int, realtime: bool = False, *, fps: float | None = None,
                stall_timeout: float = DEFAULT_STALL_TIMEOUT,
                open_timeout: float = DEFAULT_OPEN_TIMEOUT,
                clock: Callable[[], float] = time.monotonic,
                sleep: Callable[[float], None] = time.sleep, waiting: Waiting | None = None) -> FrameSource:
    """Open ``spec``: a camera index ("0" or 0), a stream URL, an image folder or a video file
    (a ``str`` or a path object); any other type is a ``SourceError``.

    Files are read as fast as pulled (timestamps ``index / fps``) or, with ``realtime``, paced at
    their frame rate (timestamps are ``clock`` readings). ``fps`` overrides or supplies a file's rate
    (an image folder has none; 30 is assumed). Live sources ignore ``realtime``, ``fps``, ``sleep``
    and ``clock``: their timestamps are ``time.monotonic()`` at grab, and a live source that delivers
    nothing for ``stall_timeout`` s raises ``SourceError("stream stalled ...")``. ``waiting`` is told
    the description of a live source still silent a couple of seconds into opening it.
    """
    if isinstance(spec, int) and not isinstance(spec, bool):
        spec = str(spec)
    elif isinstance(spec, os.PathLike):
        spec = os.fspath(spec)
    if not isinstance(spec, str):
        raise SourceError(f"a source is a path, camera index or stream URL, not {spec!r}")
    if not spec.strip():  # Path("") is the current folder: nobody means that by an empty argument
        raise SourceError("an empty source: give a video file, image folder (. for the current one), "
                          "camera index or stream URL")
    if spec.isascii() and spec.isdigit():
        return open_camera(int(spec), stall_timeout, open_timeout, waiting)
    if _URL.match(spec):
        return open_stream(spec, stall_timeout, open_timeout, waiting)
    path = Path(spec)
    if path.is_dir():
        return ImageFolderSource(path, realtime, fps, clock, sleep)
    if not path.exists():
        raise SourceError(f"no such video file or image folder: {spec}")
    return VideoFileSource(path, realtime, fps, clock, sleep)
