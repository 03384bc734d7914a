"""The motion detector with a moving camera (hand-held shake, a pan, a gimbal turning after the
subject): on a rendered scene with one moving subject the start lands on it, as with a still camera
(tests/tracker/test_detectors.py), and the strip at the edge that the earlier frames did not see is
not reported as moving."""
from __future__ import annotations

import pytest

from pipelines.loop.acquire import CAMERA_MOTION_FRACTION, StartConfirmer, pick_candidate
from tracker.runtime.boxes import Box, iou
from tracker.detectors import make_detector
from tracker.evaluation.synthetic import SyntheticSequence, render_sequence

SIZE = (640, 360)
CAMERAS = {
    "shaken by up to 4 px": dict(shake=4.0, seed=2),
    "panning 5 px a frame": dict(pan=5.0, speed=2.0, seed=1),
    "turning after the subject": dict(pan=3.0, speed=3.0, seed=1),
    "panning and shaken": dict(pan=3.0, shake=2.0, seed=1),
}


def _start(seq: SyntheticSequence) -> tuple[int, Box] | None:
    """The frame and box ``gimbaltrack track --detect motion`` starts on (3-of-5 confirmation, central pick)."""
    detector, confirmer = make_detector("motion"), StartConfirmer(max_moving_fraction=CAMERA_MOTION_FRACTION)
    for index, frame in enumerate(seq.frames):
        found = pick_candidate(confirmer.offer(detector.detect(frame), SIZE), SIZE)
        if found is not None:
            return index, found.box
    return None


@pytest.mark.parametrize("camera", CAMERAS.values(), ids=CAMERAS.keys())
def test_the_start_lands_on_the_subject_soon(camera):
    seq = render_sequence(frames=30, frame_size=SIZE, **camera)
    start = _start(seq)
    assert start is not None
    index, box = start
    assert index <= 8 and iou(box, seq.boxes[index]) > 0.6, (index, box, seq.boxes[index])


@pytest.mark.parametrize("seed", [1, 2])
def test_a_pan_reports_the_subject_alone(seed):
    """Not the strip the pan brings in, which the earlier frames never saw."""
    seq = render_sequence(frames=30, frame_size=SIZE, pan=5.0, speed=2.0, seed=seed)
    detector = make_detector("motion")
    found = [detector.detect(frame) for frame in seq.frames]
    assert all(len(f) == 1 and iou(f[0].box, truth) > 0.6 for f, truth in zip(found[3:], seq.boxes[3:])), found
