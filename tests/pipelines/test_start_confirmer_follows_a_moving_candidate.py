"""``StartConfirmer`` follows a moving candidate: a detection is matched against the candidate's
last box moved on at its velocity, so a subject crossing the picture is confirmed on its third
sighting as a still one is; detections at random places in isolated frames are not."""
from __future__ import annotations

import numpy as np
import pytest

from pipelines.acquire import StartConfirmer
from tracker.detectors import Detection

SIZE = (640, 360)


def at(x: float, y: float = 100.0) -> Detection:
    return Detection((x, y, 40.0, 80.0), 1.0)


@pytest.mark.parametrize("step", [8.0, 15.0, 20.0])  # a fifth to a half of the box's width a frame
def test_a_steady_mover_is_confirmed_on_its_third_sighting(step: float) -> None:
    confirmer = StartConfirmer()
    offered = [confirmer.offer([at(100 + step * i)], SIZE) for i in range(3)]
    assert offered == [[], [], [at(100 + 2 * step)]]


def test_a_mover_missed_in_one_frame_is_confirmed_where_it_went_on_to() -> None:
    confirmer = StartConfirmer()
    offered = [confirmer.offer(frame, SIZE) for frame in ([at(100, 40)], [at(112, 50)], [], [at(136, 70)])]
    assert offered == [[], [], [], [at(136, 70)]]


def test_detections_at_random_places_in_isolated_frames_are_never_confirmed() -> None:
    rng = np.random.default_rng(0)
    confirmer = StartConfirmer()
    for i in range(300):
        frame = [at(rng.uniform(0, 600), rng.uniform(0, 280))] if i % 2 == 0 else []
        assert confirmer.offer(frame, SIZE) == [], i
