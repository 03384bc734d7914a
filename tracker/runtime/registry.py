"""Tracker names and construction: ``make_tracker`` and ``available_trackers``."""
from __future__ import annotations

import warnings
from dataclasses import replace
from pathlib import Path

from tracker.backends import BACKEND_NAMES, MODEL_BACKENDS, make_backend
from tracker.backends.model_files import checked_model_dir
from tracker.backends.nanotrack import nanotrack_model_files
from tracker.backends.onnx_sessions import DEFAULT_THREADS
from tracker.backends.vittrack import vittrack_model_file
from tracker.detectors import Detector
from tracker.runtime.subject import SubjectTracker, TrackerSettings

#: The default: NanoTrack v3 with VitTrack's box averaged in, on the model files shipped in the
#: package (the best mean AUC on the 19 shared sequences from one start and from eight, at 60 fps or
#: more at 1280x720: docs/tracker.md), whose settings below report a hidden or departed subject as
#: lost. Where its models cannot be loaded (no onnxruntime, a damaged file) the default is
#: ``FALLBACK_BACKEND``, with one warning.
DEFAULT_BACKEND = "nanovit"
FALLBACK_BACKEND = "dcf"
#: The model trackers whose files ship inside the package, so that they need no model folder.
EMBEDDED_TRACKERS = ("nanotrack3", "nanovit")
EMBEDDED_MODELS = Path(__file__).resolve().parents[1] / "models"
# The template refinement corrects CSRT's drift; the correlation filter's own peak is finer. The
# template search may restart dcf only once the subject is lost: dcf keeps following through a few
# unsure frames, and restarting it there put it on look-alike background (docs/tracker-lab.md). The
# pixel likeness counts by its square root in its confidence: in full it doubted a subject the filter
# still held (lower over eight starts on the 19 shared sequences), not at all kept an occluder
# `tracking` (docs/tracker-lab.md, V25-V26).
# NanoTrack v3's score (foreground x deep likeness) alone decides its confidence, under a lower
# gate: the pixel likeness sank on turning subjects and pulled a subject the network still held
# under the gate (docs/tracker-lab.md, "How the default was chosen"). Its score stays high on a cover
# or on background, so a box must also pass the verification (verify_deep: its deep likeness to the
# subject as first seen, or the pixel likeness), learns the size only where the pixels agree
# (size_pixel), and takes a returning subject back at its size (return_size_ratio, search_scales; a
# weaker template match is enough where its deep likeness is strong) (docs/tracker-lab.md, "Lost-state
# reporting for nanotrack3").
_NANOTRACK3 = TrackerSettings(track_confidence=0.1, pixel_weight=0.0, verify_deep=0.85, size_pixel=0.6,
                              return_size_ratio=0.85, search_scales=(0.8, 1.0, 1.25),
                              reacquire_score=0.6, reacquire_deep_likeness=1.0, unverified_pull=1.0)
# ``nanovit``'s score and deep likeness are NanoTrack v3's, so it takes those settings; VitTrack's
# confidence at its box vouches for a box they doubt (a turning subject: docs/tracker-lab.md).
_NANOVIT = replace(_NANOTRACK3, verify_second=0.4)
_SETTINGS = {"dcf": TrackerSettings(refine_blend=0.0, reacquire_after_frames=TrackerSettings.lost_after_frames + 1,
                                    pixel_weight=0.5),
             "nanotrack3": _NANOTRACK3,
             "nanovit": _NANOVIT}


def available_trackers() -> list[str]:
    """Names ``make_tracker`` accepts; those in ``MODEL_BACKENDS`` read model files (``nanotrack3``'s
    and ``nanovit``'s ship with the package)."""
    return ["default", *BACKEND_NAMES]


def make_tracker(name: str = "default", model_dir: str | Path | None = None,
                 detector: Detector | None = None, threads: int = DEFAULT_THREADS) -> SubjectTracker:
    """A subject tracker by name; ``detector``, if given, helps it find a lost subject again;
    ``threads``: onnxruntime's intra-op threads for the models that run on it.

    ``default`` is ``DEFAULT_BACKEND`` on ``model_dir``'s files where it holds them all, else on the
    shipped files, or ``FALLBACK_BACKEND`` with a ``TrackerFallbackWarning`` where those models cannot
    be loaded.
    ``EMBEDDED_TRACKERS`` read the files shipped with the package where ``model_dir`` is not given;
    other model trackers need it. Unknown names raise ``ValueError``; missing model files, or a
    ``model_dir`` that is no folder, raise ``FileNotFoundError``; a damaged one ``ValueError``.
    """
    model_dir = checked_model_dir(model_dir)
    if name == "default":
        return _default_tracker(model_dir, detector, threads)
    if name not in BACKEND_NAMES:
        raise ValueError(f"unknown tracker {name!r} (available: {', '.join(available_trackers())})")
    if model_dir is None and name in EMBEDDED_TRACKERS:
        model_dir = EMBEDDED_MODELS
    backend = make_backend(name, model_dir, threads)  # missing model files fail here, not on init()
    model = str(model_dir) if name in MODEL_BACKENDS else None
    return SubjectTracker(name, backend, detector, _SETTINGS.get(name), model=model)


class TrackerFallbackWarning(UserWarning):
    """The default tracker's model could not be loaded here, so the fallback runs instead."""


def _default_tracker(model_dir: Path | None, detector: Detector | None, threads: int) -> SubjectTracker:
    """``DEFAULT_BACKEND`` on ``model_dir``'s NanoTrack v3 and VitTrack files, else on the shipped ones;
    where those models cannot be loaded, ``FALLBACK_BACKEND`` and one warning saying why."""
    models = model_dir if model_dir is not None and _holds_default_models(model_dir) else EMBEDDED_MODELS
    try:
        backend = make_backend(DEFAULT_BACKEND, models, threads)
    except (ValueError, FileNotFoundError) as exc:  # RuntimeMissingError (no onnxruntime) is a ValueError
        warnings.warn(f"the default tracker {DEFAULT_BACKEND} cannot run here ({exc}); using {FALLBACK_BACKEND}",
                      TrackerFallbackWarning)  # one place: shown once per process
        return SubjectTracker(FALLBACK_BACKEND, make_backend(FALLBACK_BACKEND), detector, _SETTINGS.get(FALLBACK_BACKEND))
    return SubjectTracker(DEFAULT_BACKEND, backend, detector, _SETTINGS.get(DEFAULT_BACKEND), model=str(models))


def _holds_default_models(model_dir: Path) -> bool:
    """Whether ``model_dir`` has every file ``DEFAULT_BACKEND`` reads (NanoTrack v3's and VitTrack's)."""
    try:
        nanotrack_model_files(model_dir, "v3")
        vittrack_model_file(model_dir)
    except FileNotFoundError:
        return False
    return True
