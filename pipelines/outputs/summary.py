"""The run summary: one JSON object, replaced atomically so it can be rewritten during the run."""
from __future__ import annotations

import errno
import json
import os
from collections.abc import Mapping
from typing import Any

from pipelines.outputs._files import atomic_write, to_plain


def write_summary(path: str | os.PathLike[str], summary: Mapping[str, Any], sync: bool = True) -> None:
    """Write ``summary`` to ``path`` via a temporary file and a rename; call it as often as useful
    (``sync=False`` for the rewrites during a run: no fsync, see ``atomic_write``). On a full disk
    the file is rewritten in its own space instead, when it has enough."""
    data = (json.dumps(to_plain(summary), indent=2, allow_nan=False) + "\n").encode("utf-8")
    try:
        atomic_write(path, data, sync)
    except OSError as exc:
        if exc.errno not in _DISK_FULL or not _fits_in_place(path, data):
            raise
        _overwrite(path, data)


_DISK_FULL = (errno.ENOSPC, errno.EDQUOT)


def _fits_in_place(path: str | os.PathLike[str], data: bytes) -> bool:
    """Whether ``path`` exists with room on disk already allocated to it for ``data``."""
    try:
        return os.stat(path).st_blocks * 512 >= len(data)
    except OSError:
        return False


def _overwrite(path: str | os.PathLike[str], data: bytes) -> None:
    """Rewrite ``path`` in place, in the disk space it already has: on a full disk there is no room
    for the temporary copy an atomic replacement needs, and a stale summary would hide how the run
    ended. Not atomic, but it needs no new space, so it cannot stop half-way for lack of it."""
    with open(path, "r+b") as handle:
        handle.write(data)
        handle.truncate()
        handle.flush()
        os.fsync(handle.fileno())
