"""The correlation filter follows subjects that are not square (a person is tall, a car wide): its
window is then not square either, and must be centred on each axis by that axis's size."""
from __future__ import annotations

import cv2
import pytest

from tracker.runtime.boxes import iou
from tracker.backends.dcf import DcfBackend
from tracker.evaluation.synthetic import render_sequence


@pytest.mark.parametrize("stretch", [(2, 1), (1, 2)], ids=["wide", "tall"])
def test_a_stretched_subject_is_followed(stretch: tuple[int, int]) -> None:
    sx, sy = stretch
    seq = render_sequence(frames=30, target=40, speed=2.0, seed=3)
    frames = [cv2.resize(frame, None, fx=sx, fy=sy, interpolation=cv2.INTER_LINEAR) for frame in seq.frames]
    truth = [(x * sx, y * sy, w * sx, h * sy) for x, y, w, h in seq.boxes]
    backend = DcfBackend()
    backend.init(frames[0], truth[0])
    assert min(iou(backend.update(frame)[0], box) for frame, box in zip(frames[1:], truth[1:])) > 0.8
