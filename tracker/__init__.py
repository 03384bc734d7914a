"""Vision tracker: detectors, tracking backends, re-acquisition, box Kalman, datasets, metrics.

The names below are loaded on first use (module ``__getattr__``): importing a light module such as
``tracker.runtime.boxes`` does not load the backends' OpenCV and SciPy."""
from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

_HOMES = {"SubjectTracker": "runtime.subject", "available_trackers": "runtime.registry",
          "make_tracker": "runtime.registry"}
__all__ = sorted(_HOMES)

if TYPE_CHECKING:
    from tracker.runtime.registry import available_trackers, make_tracker
    from tracker.runtime.subject import SubjectTracker


def __getattr__(name: str) -> Any:
    if name not in _HOMES:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(f"{__name__}.{_HOMES[name]}"), name)
    globals()[name] = value
    return value
