"""SubjectTracker: a backend, a box Kalman filter, a confidence and re-acquisition."""
from __future__ import annotations

import math
from dataclasses import dataclass
from numbers import Real

import numpy as np

from tracker.backends import TrackingBackend
from tracker.detectors import Detector
from tracker.runtime.appearance import AppearanceModel, Match, cut_patch
from tracker.runtime.boxes import Box, start_box
from tracker.runtime.estimate import TargetEstimate, TrackState
from tracker.runtime.frames import as_bgr_or_grey
from tracker.runtime.kalman import BoxKalman


#: A backend's box narrower or lower than this is a failure, not a subject (``_usable``).
MIN_BOX_PX = 1.0


@dataclass(frozen=True)
class TrackerSettings:
    """Global thresholds (the same for every sequence; chosen on synthetic and benchmark data)."""

    track_confidence: float = 0.25  # below this the backend's box is not trusted
    pixel_weight: float = 1.0  # confidence = backend score x pixel likeness ** this (0: the score alone)
    reacquire_after_frames: int = 3  # low-confidence frames before a search may re-initialise
    reacquire_score: float = 0.75  # template match needed to re-initialise on a found box
    reacquire_margin: float = 0.3  # ... and by how much it must beat the backend's own box
    reacquire_below_typical: float = 0.2  # ... and be at least the subject's typical likeness minus this
    reacquire_deep_likeness: float = 0.6  # ... and the backend's own likeness ratio for it at least this
    adapt_confidence: float = 0.6  # the adaptive template learns only above this
    adapt_rate: float = 0.05
    # The subject's size is learnt only from those frames whose pixel likeness reaches this too (with
    # the pixel likeness out of the confidence, a box shrinking as the subject slid behind a cover
    # taught the search a wrong size)
    size_pixel: float = 0.0
    lost_after_frames: int = 15  # consecutive low-confidence frames before declaring LOST
    refine_reach: float = 0.1  # a confident box's centre is re-matched within this many box sizes ...
    refine_blend: float = 0.5  # ... and moved this far towards the match
    search_reach: float = 1.0  # local search radius in box sizes, growing while searching
    max_reach: float = 4.0
    search_scales: tuple[float, ...] = (1.0,)  # the search's box sizes, as shares of the subject's last one
    # A check that the backend's box still holds the subject, for backends whose own score stays high on
    # a cover or on background: with verify_deep > 0 a box is trusted only when the backend's anchor
    # likeness (its features under the box against the subject as first seen, over their early value)
    # reaches verify_deep or the pixel likeness reaches verify_pixel. An unverified box is a miss, its
    # confidence the backend's score times the pixel likeness in full. 0: off (every box is verified).
    verify_deep: float = 0.0
    verify_pixel: float = 0.3
    # After misses, a box at the frame's edge is taken back only once its width and height are at least
    # this share of the subject's size: the part in view of a subject coming back in is no measure of
    # its size, and a backend that took the sliver up grows its box only slowly. 0: off.
    return_size_ratio: float = 0.0
    # A box that fails that check may still be vouched for by a second model: the backend's
    # ``second_opinion()`` (``nanovit``: VitTrack's confidence at the box) reaching this. A turning
    # subject that both the first look and the pixels no longer match keeps that model's confidence;
    # a cover or bare background does not. 0: off.
    verify_second: float = 0.0
    # While searching, the Kalman filter follows an unverified box with the backend's score times
    # this as its confidence (the state stays ``searching``, so the gimbal holds): a subject the
    # check cannot confirm is more often where the backend has it than where it was last confirmed.
    # A ``lost`` box still holds still. 0: such a box pulls with the doubted confidence only.
    unverified_pull: float = 0.0


class SubjectTracker:
    """Follows one subject; ``update`` returns a :class:`TargetEstimate` every frame.

    Each frame the backend proposes a box; its confidence is the backend's own score times
    the patch's likeness to the subject. Confident boxes feed the Kalman filter. Otherwise
    the tracker searches (template matching around the Kalman prediction, then detector
    candidates if it has a detector) and re-initialises the backend on a convincing match;
    after ``lost_after_frames`` misses it reports ``LOST`` and holds the last box.
    """

    def __init__(self, name: str, backend: TrackingBackend, detector: Detector | None = None,
                 settings: TrackerSettings | None = None, model: str | None = None) -> None:
        self.name = name
        self.model = model  # where the backend's model files came from (None: it has none)
        self._backend = backend
        self._detector = detector
        self.settings = settings or TrackerSettings()
        _check_verifications(backend, self.settings)
        self._kalman = BoxKalman()
        self._appearance: AppearanceModel | None = None
        self._size: tuple[float, float] = (0.0, 0.0)  # the subject's size when last seen confidently
        self._misses = 0
        self._frame_index = -1
        self._typical_likeness = 0.0  # the subject's running pixel likeness on its confident frames ...
        self._confident_frames = 0  # ... (their mean until there are 1 / adapt_rate of them)

    def init(self, frame: np.ndarray, box: Box, timestamp: float) -> TargetEstimate:
        """Start following ``box`` (x, y, w, h) in ``frame``; it may reach over the frame's edges
        (``ValueError`` when it misses the frame). Frames may be grey, BGR or BGRA."""
        frame = as_bgr_or_grey(frame)
        _check_timestamp(timestamp)
        height, width = frame.shape[:2]
        box = start_box(tuple(float(v) for v in box), width, height)
        self._appearance = AppearanceModel(frame, box)
        self._typical_likeness, self._confident_frames = 0.0, 0
        self._restart(frame, box, timestamp)
        self._frame_index = 0
        return self._estimate(1.0, TrackState.TRACKING, timestamp)

    def update(self, frame: np.ndarray, timestamp: float) -> TargetEstimate:
        """Follow the subject into ``frame`` captured at ``timestamp`` (seconds)."""
        if self._appearance is None:
            raise RuntimeError("SubjectTracker.update() before init()")
        frame = as_bgr_or_grey(frame)
        _check_timestamp(timestamp)
        self._frame_index += 1
        s = self.settings
        predicted = self._kalman.predict(timestamp)
        box, backend_score = _usable(*self._backend.update(frame))
        patch = cut_patch(frame, box) if box is not None else None
        similarity = self._appearance.similarity(patch) if patch is not None else 0.0
        confidence = backend_score * similarity ** s.pixel_weight
        verified = box is not None and self._holds_subject(frame, box, similarity) and not self._a_sliver(frame, box)
        if not verified:
            confidence = min(confidence, backend_score * similarity)
        if verified and confidence >= s.track_confidence:  # verified: there is a box
            return self._accept(frame, box, patch, similarity, confidence, timestamp)
        self._misses += 1
        found = self._search(frame, predicted) if self._misses >= s.reacquire_after_frames else Match(predicted, 0.0)
        needed = max(s.reacquire_score, similarity + s.reacquire_margin,
                     self._typical_likeness - s.reacquire_below_typical)
        if found.score >= needed and self._backend_likes(frame, found.box):
            self._restart(frame, found.box, timestamp)
            return self._estimate(found.score, TrackState.TRACKING, timestamp)
        if self._misses > s.lost_after_frames:
            self._kalman.stop()
            return self._estimate(confidence, TrackState.LOST, timestamp)
        if box is not None:
            pull = backend_score * s.unverified_pull if not verified else 0.0
            self._kalman.correct(box, max(confidence, pull))
        return self._estimate(confidence, TrackState.SEARCHING, timestamp)

    def _holds_subject(self, frame: np.ndarray, box: Box, similarity: float) -> bool:
        """Whether the backend's ``box`` passes the check ``verify_deep`` switches on (True when off):
        by its pixels, its deep likeness to the first look, or a second model's confidence. The second
        model is not asked about a box at the frame's edge: its confidence there is in the part still
        in view of a subject leaving the picture, not in the box, which lags behind it."""
        s = self.settings
        if s.verify_deep <= 0.0 or similarity >= s.verify_pixel or self._backend.anchor_likeness() >= s.verify_deep:
            return True
        return (s.verify_second > 0.0 and not self._at_edge(frame, box)
                and self._backend.second_opinion() >= s.verify_second)

    def _at_edge(self, frame: np.ndarray, box: Box) -> bool:
        """Whether ``box`` reaches within a tenth of the subject's size of the frame's border."""
        (w, h), (x, y, bw, bh) = self._size, box
        height, width = frame.shape[:2]
        margin = 0.1 * max(w, h)
        return x <= margin or y <= margin or x + bw >= width - margin or y + bh >= height - margin

    def _a_sliver(self, frame: np.ndarray, box: Box) -> bool:
        """Whether ``box``, after misses, is at the frame's edge and smaller than ``return_size_ratio``
        of the subject's size: the part in view of a subject coming back into the picture."""
        ratio = self.settings.return_size_ratio
        if ratio <= 0.0 or self._misses == 0:
            return False
        (w, h), (_, _, bw, bh) = self._size, box
        return self._at_edge(frame, box) and (bw < ratio * w or bh < ratio * h)

    def _backend_likes(self, frame: np.ndarray, box: Box) -> bool:
        """Whether the backend's own likeness of ``box`` to the subject (relative to its typical
        value; backends that cannot score boxes say 1) reaches ``reacquire_deep_likeness``."""
        bar = self.settings.reacquire_deep_likeness
        score = getattr(self._backend, "likeness", None)
        return bar <= 0.0 or score is None or score(frame, box) >= bar

    def _accept(self, frame: np.ndarray, box: Box, patch: np.ndarray, similarity: float, confidence: float,
                timestamp: float) -> TargetEstimate:
        s = self.settings
        self._misses = 0
        if confidence >= s.adapt_confidence:
            self._confident_frames += 1
            rate = max(s.adapt_rate, 1.0 / self._confident_frames)
            self._typical_likeness += rate * (similarity - self._typical_likeness)
            if similarity >= s.size_pixel:
                self._size = (box[2], box[3])  # not a box shrinking as the subject slides out of sight
            self._appearance.adapt(patch, s.adapt_rate)  # the patch the similarity was measured on
        if s.refine_blend > 0:
            box = self._refine(frame, box)
        self._kalman.correct(box, confidence)
        return self._estimate(confidence, TrackState.TRACKING, timestamp)

    def _refine(self, frame: np.ndarray, box: Box) -> Box:
        """The box moved part-way towards the best template match near it (same size)."""
        found = self._appearance.search(frame, box, (box[2], box[3]), self.settings.refine_reach)
        if found.score <= 0.0:
            return box
        blend = self.settings.refine_blend
        return (box[0] + blend * (found.box[0] - box[0]), box[1] + blend * (found.box[1] - box[1]), box[2], box[3])

    def _restart(self, frame: np.ndarray, box: Box, timestamp: float) -> None:
        self._backend.init(frame, box)  # (re)starts the backend from scratch on this box
        self._kalman.reset(box, timestamp)
        self._size = (box[2], box[3])
        self._misses = 0

    def _search(self, frame: np.ndarray, predicted: Box) -> Match:
        """Template search around the prediction, widening while the subject stays unseen, for a
        box of the subject's size on its last confident frame (times each of ``search_scales``: a
        subject may come back from behind a cover nearer or farther, as on the demo clip)."""
        s = self.settings
        reach = min(s.max_reach, s.search_reach * (1.0 + 0.25 * self._misses))
        w, h = self._size
        best = max((self._appearance.search(frame, predicted, (w * k, h * k), reach / k) for k in s.search_scales),
                   key=lambda match: match.score)
        if self._detector is not None and self._misses > s.lost_after_frames:
            for detection in self._detector.detect(frame):
                found = self._in_detection(frame, detection.box)
                if found.score > best.score:
                    best = found
        return best

    def _in_detection(self, frame: np.ndarray, box: Box) -> Match:
        """The subject in a detector's ``box``: the whole box by its likeness, or the best match of
        the subject's templates at the subject's size inside it (centred on it when it is smaller),
        whichever looks more like it. A start on part of the subject (a motion box that caught half
        of it) learnt that part's look, which a box of the whole subject does not resemble."""
        whole = Match(box, self._appearance.similarity(cut_patch(frame, box)))
        w, h = self._size
        inside = self._appearance.search(frame, box, self._size, max(0.0, (box[2] / w - 1) / 2, (box[3] / h - 1) / 2))
        return inside if inside.score > whole.score else whole

    def _estimate(self, confidence: float, state: TrackState, timestamp: float) -> TargetEstimate:
        box = self._kalman.box
        return TargetEstimate(box=box, velocity=self._kalman.velocity, confidence=float(np.clip(confidence, 0, 1)),
                              state=state, timestamp=timestamp, frame_index=self._frame_index)


def _check_verifications(backend: TrackingBackend, settings: TrackerSettings) -> None:
    """``ValueError`` where ``settings`` switch on a check ``backend`` cannot make: a check that is
    skipped would trust every box the backend gives."""
    needs = {"anchor_likeness": settings.verify_deep > 0.0, "second_opinion": settings.verify_second > 0.0}
    missing = [name for name, needed in needs.items() if needed and getattr(backend, name, None) is None]
    if missing:
        raise ValueError(f"tracker settings need the backend's {', '.join(missing)}, which {backend.name} lacks")


def _check_timestamp(timestamp: float) -> None:
    """``ValueError`` unless ``timestamp`` is a finite number of seconds (the Kalman filter's clock)."""
    if isinstance(timestamp, bool) or not isinstance(timestamp, Real) or not math.isfinite(timestamp):
        raise ValueError(f"a frame's timestamp must be a finite number of seconds, not {timestamp!r}")


def _usable(box: Box | None, score: float) -> tuple[Box | None, float]:
    """A backend's answer with a numerical failure (a non-finite box, one under a pixel wide or
    high, a NaN score) turned into a miss, so it never reaches the Kalman filter or the gimbal's
    controller."""
    if not math.isfinite(score):
        score = 0.0
    if box is not None and not (all(math.isfinite(v) for v in box) and box[2] >= MIN_BOX_PX and box[3] >= MIN_BOX_PX):
        return None, 0.0
    return box, score
