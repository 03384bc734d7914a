"""The run summary: one JSON object, replaced atomically so it can be rewritten during the run."""
from __future__ import annotations

import json
import os
from collections.abc import Mapping
from typing import Any

from pipelines.outputs._files import atomic_write, to_plain


def write_summary(path: str | os.PathLike[str], summary: Mapping[str, Any], sync: bool = True) -> None:
    """Write ``summary`` to ``path`` via a temporary file and a rename; call it as often as useful
    (``sync=False`` for the rewrites during a run: no fsync, see ``atomic_write``)."""
    text = json.dumps(to_plain(summary), indent=2, allow_nan=False) + "\n"
    atomic_write(path, text.encode("utf-8"), sync)
