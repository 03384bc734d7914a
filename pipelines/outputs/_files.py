"""Helpers the outputs share: JSON-ready values and atomic file replacement."""
from __future__ import annotations

import dataclasses
import math
import os
from collections.abc import Mapping
from enum import Enum
from pathlib import Path
from typing import Any

import numpy as np


def to_plain(value: Any) -> Any:
    """A JSON-ready copy: numpy values, enums, tuples and dataclasses converted; NaN/inf become None."""
    if isinstance(value, Enum):
        return to_plain(value.value)
    if isinstance(value, np.generic):
        return to_plain(value.item())
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if value is None or isinstance(value, (str, int)):
        return value
    if isinstance(value, Mapping):
        return {str(key): to_plain(item) for key, item in value.items()}
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return {field.name: to_plain(getattr(value, field.name)) for field in dataclasses.fields(value)}
    if isinstance(value, (list, tuple, np.ndarray)):
        return [to_plain(item) for item in value]
    raise TypeError(f"cannot write {type(value).__name__} as JSON")


def atomic_write(path: str | os.PathLike[str], data: bytes, sync: bool = True) -> None:
    """Replace ``path`` with ``data`` in one step: readers see the old or the new file, never a torn one.

    ``sync`` forces the data to disk before the rename (survives a power loss); without it a
    process crash still leaves the old or the new file, and the write costs no disk flush."""
    target = Path(path)
    tmp = target.with_name(f".{target.name}.{os.getpid()}.tmp")
    try:
        with open(tmp, "wb") as handle:
            handle.write(data)
            handle.flush()
            if sync:
                os.fsync(handle.fileno())
        os.replace(tmp, target)
    finally:
        tmp.unlink(missing_ok=True)
