"""Tracker names and construction: ``make_tracker`` and ``available_trackers``."""
from __future__ import annotations

from pathlib import Path

from tracker.backends import BACKEND_NAMES, make_backend
from tracker.detectors import Detector
from tracker.model_files import checked_model_dir
from tracker.nanotrack import nanotrack_model_files
from tracker.subject import SubjectTracker, TrackerSettings

DEFAULT_BACKEND = "dcf"  # best measured without model files (docs/tracker.md)
DEFAULT_WITH_MODELS = "nanotrack"  # best measured when the NanoTrack files are given
# The template refinement corrects CSRT's drift; the correlation filter's own peak is finer. The
# template search may restart dcf only once the subject is lost: dcf keeps following through a few
# unsure frames, and restarting it there put it on look-alike background (docs/tracker.md).
_SETTINGS = {"dcf": TrackerSettings(refine_blend=0.0, reacquire_after_frames=TrackerSettings.lost_after_frames + 1)}


def available_trackers() -> list[str]:
    """Names ``make_tracker`` accepts; ``nanotrack`` and ``nano`` also need the NanoTrack model files."""
    return ["default", *BACKEND_NAMES]


def make_tracker(name: str = "default", model_dir: str | Path | None = None,
                 detector: Detector | None = None) -> SubjectTracker:
    """A subject tracker by name; ``detector``, if given, helps it find a lost subject again.

    ``default`` picks NanoTrack when ``model_dir`` holds its files, else the correlation filter.
    Unknown names raise ``ValueError``; missing model files, or a ``model_dir`` that is no folder,
    raise ``FileNotFoundError``.
    """
    model_dir = checked_model_dir(model_dir)
    if name == "default":
        name = DEFAULT_WITH_MODELS if model_dir is not None and _has_nanotrack(model_dir) else DEFAULT_BACKEND
    if name not in BACKEND_NAMES:
        raise ValueError(f"unknown tracker {name!r} (available: {', '.join(available_trackers())})")
    backend = make_backend(name, model_dir)  # missing model files fail here, not on init()
    return SubjectTracker(name, backend, detector, _SETTINGS.get(name))


def _has_nanotrack(model_dir: str | Path) -> bool:
    try:
        nanotrack_model_files(model_dir)
    except FileNotFoundError:
        return False
    return True
