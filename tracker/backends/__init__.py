"""Tracking backends: one small interface over our correlation filter, the model-based trackers
(NanoTrack v2 and v3, VitTrack, FEAR-XS) and OpenCV's trackers."""
from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Protocol

import cv2
import numpy as np

from tracker.backends.dcf import DcfBackend
from tracker.backends.fear import FearBackend
from tracker.backends.fused import FusedBackend
from tracker.backends.nanotrack import (NANOVIT_PARAMS, V3_PARAMS, NanoTrackBackend, OrtNanoNetworks,
                                        load_nanotrack_networks, nanotrack_model_files)
from tracker.backends.onnx_sessions import DEFAULT_THREADS
from tracker.backends.vittrack import VitTrackBackend
from tracker.runtime.boxes import Box, cut_to_frame
from tracker.runtime.frames import as_bgr, as_bgr_or_grey


#: The optional checks of a backend's last box that take no frame (see ``TrackingBackend``).
VERIFICATIONS = ("anchor_likeness", "second_opinion")


class TrackingBackend(Protocol):
    """Follows one box from frame to frame; knows nothing about loss or re-acquisition. A backend
    may also offer ``likeness(frame, box)``: a box's likeness to the subject in its own features over
    their typical value, which a re-acquisition must then reach (``NanoTrackBackend``), and
    ``anchor_likeness()``: the last box's likeness to the subject as first seen, over its early value,
    which the subject tracker may require of a box before trusting it (``TrackerSettings.verify_deep``),
    and ``second_opinion()``: an independent model's confidence in the last box, which may vouch for
    a box that check doubts (``TrackerSettings.verify_second``)."""

    name: str

    def init(self, frame: np.ndarray, box: Box) -> None:
        """Start on ``box`` in ``frame``, forgetting anything learnt before (called again to restart)."""

    def update(self, frame: np.ndarray) -> tuple[Box | None, float]:
        """The new box (``None`` when the backend gives up) and its own score in 0..1."""


class ConvertingBackend:
    """A backend handed every frame in a format it takes, whatever the caller's: grey (H x W or
    H x W x 1), BGR or BGRA ``uint8``. BGR frames pass as they are."""

    def __init__(self, backend: TrackingBackend, convert: Callable[[np.ndarray], np.ndarray]) -> None:
        self.name = backend.name
        self._backend = backend
        self._convert = convert

    def init(self, frame: np.ndarray, box: Box) -> None:
        self._backend.init(self._convert(frame), box)

    def update(self, frame: np.ndarray) -> tuple[Box | None, float]:
        return self._backend.update(self._convert(frame))

    def likeness(self, frame: np.ndarray, box: Box) -> float:
        """The wrapped backend's likeness of ``box`` to the subject, relative to its typical value
        (1 for a backend that cannot score boxes)."""
        score = getattr(self._backend, "likeness", None)
        return score(self._convert(frame), box) if score is not None else 1.0

    def __getattr__(self, name: str) -> Callable[[], float]:
        """The wrapped backend's frame-free checks (``VERIFICATIONS``) where it has them, so that a
        check the backend lacks stays missing here too (the subject tracker refuses settings that
        need it) instead of passing every box."""
        if name in VERIFICATIONS:
            return getattr(self._backend, name)
        raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")


class OpenCvBackend:
    """Any ``cv2.Tracker``; the score is 1 when it reports success, else 0 (or its own score)."""

    def __init__(self, name: str, create: Callable[[], cv2.Tracker],
                 score: Callable[[cv2.Tracker], float] | None = None) -> None:
        self.name = name
        self._create = create
        self._score = score
        self._tracker: cv2.Tracker | None = None

    def init(self, frame: np.ndarray, box: Box) -> None:
        self._tracker = self._create()
        height, width = frame.shape[:2]
        self._tracker.init(frame, _int_box(cut_to_frame(box, width, height)))  # some crash on a box over an edge

    def update(self, frame: np.ndarray) -> tuple[Box | None, float]:
        if self._tracker is None:
            raise RuntimeError(f"{self.name}: update() before init()")
        ok, box = self._tracker.update(frame)
        if not ok:
            return None, 0.0
        score = self._score(self._tracker) if self._score else 1.0
        return tuple(float(v) for v in box), float(np.clip(score, 0.0, 1.0))


def _int_box(box: Box) -> tuple[int, int, int, int]:
    x, y, w, h = box
    return (int(round(x)), int(round(y)), max(1, int(round(w))), max(1, int(round(h))))


def _csrt(**overrides: float | bool) -> Callable[[], cv2.Tracker]:
    def create() -> cv2.Tracker:
        params = cv2.TrackerCSRT_Params()
        for key, value in overrides.items():
            setattr(params, key, value)
        return cv2.TrackerCSRT_create(params)
    return create


# CSRT without colour segmentation: somewhat faster than OpenCV's defaults and as accurate
# (docs/tracker-lab.md). A smaller template was faster still, but its scale estimate stopped
# following a zoom on some CPUs (tests/tracker/runtime/test_subject_tracker.py, scale change); fewer scale
# samples broke that test too.
FAST_CSRT = {"use_segmentation": False}


def _nano(model_dir: str | Path | None) -> Callable[[], cv2.Tracker]:
    """OpenCV's TrackerNano, made once: it reads its model files itself (it takes paths only) and
    its init() starts afresh, so the one tracker serves every (re)start and the files are read
    once. A start and a search on a blank frame try both networks here: on a ``cv2.error`` the
    files are checked (``load_nanotrack_networks``) so the ``ValueError`` names the bad one,
    here rather than mid-run."""
    backbone, head = nanotrack_model_files(model_dir)
    params = cv2.TrackerNano_Params()
    params.backbone, params.neckhead = str(backbone), str(head)
    try:
        tracker = cv2.TrackerNano_create(params)
        blank = np.zeros((2 * _NANO_PROBE_BOX, 2 * _NANO_PROBE_BOX, 3), np.uint8)
        tracker.init(blank, (_NANO_PROBE_BOX // 2, _NANO_PROBE_BOX // 2, _NANO_PROBE_BOX, _NANO_PROBE_BOX))
        tracker.update(blank)
    except cv2.error as exc:
        load_nanotrack_networks(model_dir)
        reason = str(exc).strip().splitlines()[-1]
        raise ValueError(f"OpenCV's TrackerNano cannot use {backbone} and {head}: {reason}") from exc
    return lambda: tracker


_NANO_PROBE_BOX = 32  # side of the box the model-file check starts TrackerNano on, pixels


BACKEND_NAMES = ("dcf", "nanotrack", "nanotrack3", "nanovit", "vittrack", "fear", "csrt-fast", "csrt", "kcf", "mil",
                 "mosse", "nano")
# Backends that need model files (``model_dir``); the last four run on onnxruntime.
MODEL_BACKENDS = ("nanotrack", "nano", "nanotrack3", "nanovit", "vittrack", "fear")
# OpenCV's KCF and Nano fail on grey frames; the others take grey as it is (cheaper than three channels).
NEEDS_BGR = ("kcf", "nano")


def make_backend(name: str, model_dir: str | Path | None = None, threads: int = DEFAULT_THREADS) -> TrackingBackend:
    """A fresh backend by name (one of ``BACKEND_NAMES``) taking grey, BGR and BGRA frames; those in
    ``MODEL_BACKENDS`` need ``model_dir``; ``threads`` is onnxruntime's intra-op thread count."""
    return ConvertingBackend(_bare_backend(name, model_dir, threads), as_bgr if name in NEEDS_BGR else as_bgr_or_grey)


def _bare_backend(name: str, model_dir: str | Path | None, threads: int) -> TrackingBackend:
    """The backend by name, taking frames in whichever formats it takes itself."""
    if name == "dcf":
        return DcfBackend()
    if name == "nanotrack":
        return NanoTrackBackend(model_dir)
    if name == "nanotrack3":
        return NanoTrackBackend(model_dir, V3_PARAMS, OrtNanoNetworks(model_dir, threads), name)
    if name == "nanovit":
        nano = NanoTrackBackend(model_dir, NANOVIT_PARAMS, OrtNanoNetworks(model_dir, threads), "nanotrack3")
        return FusedBackend(nano, VitTrackBackend(model_dir, threads=threads), name=name)
    if name == "vittrack":
        return VitTrackBackend(model_dir, threads=threads)
    if name == "fear":
        return FearBackend(model_dir, threads=threads)
    if name == "csrt-fast":
        return OpenCvBackend(name, _csrt(**FAST_CSRT))
    if name == "csrt":
        return OpenCvBackend(name, _csrt())
    if name == "kcf":
        return OpenCvBackend(name, cv2.TrackerKCF_create)
    if name == "mil":
        return OpenCvBackend(name, cv2.TrackerMIL_create)
    if name == "mosse":
        return OpenCvBackend(name, cv2.legacy.TrackerMOSSE_create)
    if name == "nano":
        return OpenCvBackend(name, _nano(model_dir), score=lambda t: t.getTrackingScore())
    raise ValueError(f"unknown tracking backend {name!r} (known: {', '.join(BACKEND_NAMES)})")
