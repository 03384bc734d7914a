"""A NaN control setting, a camera size that is no whole number of pixels, a NaN or infinite
focal length, and a controller clock that is not finite or runs backwards are refused by name
(they were accepted and later a 'cannot clamp NaN' or a silent zero output, e.g. feedforward=NaN)."""
from __future__ import annotations

import dataclasses
import math

import pytest

from pipelines.control import CameraModel, make_controller
from pipelines.control.controller import ControlConfig
from tracker.estimate import TargetEstimate, TrackState

CAM = CameraModel(640, 360)
ESTIMATE = TargetEstimate(box=(400.0, 200.0, 40.0, 40.0), velocity=(0.0, 0.0), confidence=0.9,
                          state=TrackState.TRACKING, timestamp=0.0, frame_index=1)


@pytest.mark.parametrize("name", [f.name for f in dataclasses.fields(ControlConfig)])
def test_a_nan_setting_is_refused_by_name(name: str) -> None:
    with pytest.raises(ValueError, match=f"ControlConfig.{name} must be a number, not nan"):
        ControlConfig(**{name: math.nan})


@pytest.mark.parametrize("size", [(math.nan, 360), (640.5, 360), (None, 360), (640, True)])
def test_a_camera_size_must_be_whole_pixels(size) -> None:
    with pytest.raises(ValueError, match="whole pixels"):
        CameraModel(*size)


@pytest.mark.parametrize("focal", [math.nan, math.inf])
def test_a_focal_length_must_be_finite(focal: float) -> None:
    with pytest.raises(ValueError, match="focal_px must be positive and finite"):
        CameraModel(640, 360, focal_px=focal)


@pytest.mark.parametrize("name", ["pid", "p"])
@pytest.mark.parametrize("times", [(math.nan,), (1.0, math.inf), (1.0, 0.5)])
def test_the_clock_must_be_finite_and_not_run_backwards(name: str, times: tuple[float, ...]) -> None:
    controller = make_controller(name, camera=CAM)
    *before, bad = times
    for now in before:
        controller.update(ESTIMATE, (0.0, 0.0), now)
    with pytest.raises(ValueError, match=f"now={bad!r} must be a finite time"):
        controller.update(ESTIMATE, (0.0, 0.0), bad)
