"""A tracking backend that answers from a script, for tests of what the subject tracker makes of
its answers (misses, weak or offset boxes, restarts)."""
from __future__ import annotations

from collections.abc import Callable

import numpy as np

from tracker.runtime.boxes import Box
from tracker.detectors import Detection, Detector
from tracker.runtime.estimate import TargetEstimate, TrackState
from tracker.runtime.subject import SubjectTracker, TrackerSettings
from tracker.evaluation.synthetic import SyntheticSequence, texture

FPS = 30.0
Answer = tuple[Box | None, float]
Script = Callable[[int, int], Answer]


class ScriptedBackend:
    """``answer(n, restarts)`` is the backend's reply on the n-th frame after the tracker's start
    (1, 2, ..., counted across restarts) after ``restarts`` re-initialisations; ``inits`` holds the
    frame number of every (re)initialisation."""

    name = "scripted"

    def __init__(self, answer: Script) -> None:
        self._answer = answer
        self.frame = 0
        self.inits: list[int] = []

    def init(self, frame: np.ndarray, box: Box) -> None:
        self.inits.append(self.frame)

    def update(self, frame: np.ndarray) -> Answer:
        self.frame += 1
        return self._answer(self.frame, len(self.inits) - 1)


def on_truth(seq: SyntheticSequence, score: float = 0.9) -> Script:
    """A script that answers the subject's true box with ``score``."""
    return lambda n, restarts: (tuple(float(v) for v in seq.boxes[n]), score)


def gives_up(at: int, answer: Script) -> Script:
    """``answer``, except nothing from frame ``at`` until the backend is restarted."""
    return lambda n, restarts: (None, 0.0) if n >= at and not restarts else answer(n, restarts)


def scripted_tracker(answer: Script, detector: Detector | None = None,
                     **settings: float) -> tuple[SubjectTracker, ScriptedBackend]:
    """A subject tracker on a :class:`ScriptedBackend` (``settings`` override :class:`TrackerSettings`)."""
    backend = ScriptedBackend(answer)
    return SubjectTracker("scripted", backend, detector, TrackerSettings(**settings)), backend


def follow(subject: SubjectTracker, frames: list[np.ndarray], first: int = 1) -> list[TargetEstimate]:
    """``subject.update`` on ``frames``, the first being frame ``first`` of the run (30 fps)."""
    return [subject.update(frame, (first + i) / FPS) for i, frame in enumerate(frames)]


def empty_scene(seed: int = 0) -> np.ndarray:
    """The background of ``render_sequence(seed=seed)`` (default size) without its subject."""
    return texture(240, 320, np.random.default_rng(seed), cell=16, contrast=0.35)


def wide_scene(places: list[Box | None]) -> list[np.ndarray]:
    """640 x 480 frames of a textured scene with a 40 px textured subject at each frame's place
    (its top-left corner; None: out of the picture)."""
    rng = np.random.default_rng(11)
    background = texture(480, 640, rng, cell=16, contrast=0.35)
    look = texture(40, 40, rng, cell=6, contrast=1.0)
    frames = []
    for place in places:
        frame = background.copy()
        if place is not None:
            x, y = int(place[0]), int(place[1])
            frame[y:y + 40, x:x + 40] = look
        frames.append(frame)
    return frames


class BackgroundAndSubject:
    """A detector that proposes a patch of ``background`` and, while ``subject_in_view``, ``subject``."""

    def __init__(self, background: Box, subject: Box) -> None:
        self.background, self.subject = background, subject
        self.subject_in_view = True

    def detect(self, frame: np.ndarray) -> list[Detection]:
        return [Detection(self.background, 0.9)] + ([Detection(self.subject, 0.8)] if self.subject_in_view else [])


def restarted_by_detection(frames: list[np.ndarray], gone: int, back: int, start: Box, restarted: Box,
                           detector: BackgroundAndSubject) -> tuple[list[TargetEstimate], list[int]]:
    """A scripted tracker started on ``start``: its backend follows until frame ``gone``, then finds
    nothing, and answers ``restarted`` once it has been restarted; the ``detector`` sees the subject
    from frame ``back`` on. Checks the subject was LOST before ``back``; the estimates from ``back``
    on and the frames of the backend's (re)starts."""
    subject, backend = scripted_tracker(lambda n, restarts: (start, 0.9) if n < gone else
                                        (restarted, 0.9) if restarts else (None, 0.0), detector)
    subject.init(frames[0], start, 0.0)
    detector.subject_in_view = False
    assert follow(subject, frames[1:back])[-1].state is TrackState.LOST
    detector.subject_in_view = True
    return follow(subject, frames[back:], first=back), backend.inits
