"""NanoTrack v3 and VitTrack fused: two models' boxes averaged where the second one is sure of its own.

NanoTrack v3 is the more accurate of the two over the shared sequences and the faster, but its
foreground score stays high on background; VitTrack loses more subjects for good, but its
confidence means something. So NanoTrack follows every frame, VitTrack searches around NanoTrack's
box on the same frame, and where VitTrack's windowed confidence is ``fuse_above`` or more the box
is the weighted mean of the two (their errors are partly independent, so the mean is closer to the
subject on most sequences: docs/tracker-lab.md); elsewhere NanoTrack's box stands. NanoTrack keeps
its own state: searching from the fused box instead lost subjects it had held. The score is
NanoTrack's, so the subject tracker's confidence gate and lost-subject reporting stay as they are
for ``nanotrack3``.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tracker.backends.nanotrack import NanoTrackBackend
from tracker.backends.vittrack import VitTrackBackend
from tracker.runtime.boxes import Box


@dataclass(frozen=True)
class FusionParams:
    """When and how much VitTrack's box counts."""

    fuse_above: float = 0.2  # VitTrack's windowed confidence from which its box is averaged in
    vit_weight: float = 0.5  # its weight in the mean


class FusedBackend:
    """``TrackingBackend`` over NanoTrack v3 (``primary``, which also gives the score) and VitTrack
    (``checker``, which searches where the primary's box is)."""

    def __init__(self, primary: NanoTrackBackend, checker: VitTrackBackend, params: FusionParams | None = None,
                 name: str = "nanovit") -> None:
        self.name = name
        self.params = params or FusionParams()
        self._primary = primary
        self._checker = checker
        self._checker_confidence = 0.0

    def init(self, frame: np.ndarray, box: Box) -> None:
        self._primary.init(frame, box)
        self._checker.init(frame, box)

    def update(self, frame: np.ndarray) -> tuple[Box | None, float]:
        box, score = self._primary.update(frame)
        self._checker_confidence = 0.0
        if box is None:
            return box, score
        self._checker.relocate(box)
        checked, confidence = self._checker.update(frame)
        self._checker_confidence = confidence if checked is not None else 0.0
        if checked is None or confidence < self.params.fuse_above:
            return box, score
        weight = self.params.vit_weight
        return tuple(float((1 - weight) * a + weight * b) for a, b in zip(box, checked)), score

    def likeness(self, frame: np.ndarray, box: Box) -> float:
        """The primary's likeness of ``box`` to the subject (see ``NanoTrackBackend.likeness``)."""
        return self._primary.likeness(frame, box)

    def anchor_likeness(self) -> float:
        """The primary's likeness to the subject as first seen (see ``NanoTrackBackend.anchor_likeness``),
        so the subject tracker's verification holds for the fused tracker as for ``nanotrack3``."""
        return self._primary.anchor_likeness()

    def second_opinion(self) -> float:
        """VitTrack's windowed confidence at the primary's last box (0 where it gave no box): an
        opinion independent of NanoTrack's score and features, which stays up on a subject turning
        out of its first look and falls on a cover (``TrackerSettings.verify_second``)."""
        return self._checker_confidence
