"""Tracker names and construction: ``make_tracker`` and ``available_trackers``."""
from __future__ import annotations

from pathlib import Path

from tracker.backends import BACKEND_NAMES, MODEL_BACKENDS, make_backend
from tracker.backends.model_files import checked_model_dir
from tracker.backends.nanotrack import nanotrack_model_files
from tracker.backends.onnx_sessions import DEFAULT_THREADS
from tracker.detectors import Detector
from tracker.runtime.subject import SubjectTracker, TrackerSettings

#: The default: the correlation filter. NanoTrack v3 scores higher on the 19 shared sequences
#: (docs/tracker.md) but on the suite's rendered occlusion clips it goes on saying "tracking" after
#: the subject has gone, and a gimbal must not chase background; it is there by name.
DEFAULT_BACKEND = "dcf"
DEFAULT_WITH_MODELS = "nanotrack"  # the default when the model folder holds NanoTrack v2's files
#: The model tracker whose files ship inside the package, so that it needs no model folder.
EMBEDDED_TRACKER = "nanotrack3"
EMBEDDED_MODELS = Path(__file__).resolve().parents[1] / "models"
# The template refinement corrects CSRT's drift; the correlation filter's own peak is finer. The
# template search may restart dcf only once the subject is lost: dcf keeps following through a few
# unsure frames, and restarting it there put it on look-alike background (docs/tracker-lab.md). The
# pixel likeness counts by its square root in its confidence: in full it doubted a subject the filter
# still held (lower over eight starts on the 19 shared sequences), not at all kept an occluder
# `tracking` (docs/tracker-lab.md, V25-V26).
# NanoTrack v3's score (foreground x deep likeness) alone decides its confidence, under a lower
# gate: the pixel likeness sank on turning subjects and pulled a subject the network still held
# under the gate (docs/tracker-lab.md, "How the default was chosen").
_SETTINGS = {"dcf": TrackerSettings(refine_blend=0.0, reacquire_after_frames=TrackerSettings.lost_after_frames + 1,
                                    pixel_weight=0.5),
             "nanotrack3": TrackerSettings(track_confidence=0.1, pixel_weight=0.0)}


def available_trackers() -> list[str]:
    """Names ``make_tracker`` accepts; those in ``MODEL_BACKENDS`` read model files (``nanotrack3``'s
    ship with the package)."""
    return ["default", *BACKEND_NAMES]


def make_tracker(name: str = "default", model_dir: str | Path | None = None,
                 detector: Detector | None = None, threads: int = DEFAULT_THREADS) -> SubjectTracker:
    """A subject tracker by name; ``detector``, if given, helps it find a lost subject again;
    ``threads``: onnxruntime's intra-op threads for the models that run on it.

    ``default`` is NanoTrack (v2) when ``model_dir`` holds its files, else the correlation filter.
    ``EMBEDDED_TRACKER`` reads the files shipped with the package where ``model_dir`` is not given;
    other model trackers need it. Unknown names raise ``ValueError``; missing model files, or a
    ``model_dir`` that is no folder, raise ``FileNotFoundError``; a damaged one ``ValueError``.
    """
    model_dir = checked_model_dir(model_dir)
    if name == "default":
        name = DEFAULT_WITH_MODELS if model_dir is not None and _has_nanotrack(model_dir) else DEFAULT_BACKEND
    if name not in BACKEND_NAMES:
        raise ValueError(f"unknown tracker {name!r} (available: {', '.join(available_trackers())})")
    if model_dir is None and name == EMBEDDED_TRACKER:
        model_dir = EMBEDDED_MODELS
    backend = make_backend(name, model_dir, threads)  # missing model files fail here, not on init()
    model = str(model_dir) if name in MODEL_BACKENDS else None
    return SubjectTracker(name, backend, detector, _SETTINGS.get(name), model=model)


def _has_nanotrack(model_dir: Path) -> bool:
    try:
        nanotrack_model_files(model_dir)
    except FileNotFoundError:
        return False
    return True
