"""Yaw errors and commands when the gimbal and an off-centre target straddle +-180 deg."""
import pytest

from pipelines.control.camera import CameraModel
from pipelines.control.controller import RateController
from pipelines.control.direction import Direction, DirectionFilter, wrap_deg
from tracker.estimate import TargetEstimate, TrackState

CAM = CameraModel(640, 360)


def test_an_off_centre_target_across_the_wrap_keeps_a_small_error_and_the_same_direction() -> None:
    """The gimbal pans through 180 deg with the target 20 px right of the centre (~2.2 deg): for the
    frames where one is past the wrap and the other not, the error is not ~360 deg and the gimbal
    is not sent the other way."""
    controller = RateController(CAM)
    for i in range(90):
        t = i / 30
        attitude = (wrap_deg(170.0 + 10.0 * t), 0.0)
        estimate = TargetEstimate((330.0, 170.0, 20.0, 20.0), (0.0, 0.0), 0.9, TrackState.TRACKING, t, i)
        command = controller.update(estimate, attitude, t)
        assert abs(command.yaw_error_deg) < 5.0
        assert command.yaw_dps >= 0.0


def test_the_filtered_yaw_is_wrapped() -> None:
    """The filter keeps yaw unwrapped inside; what it hands out is in [-180, 180)."""
    kf = DirectionFilter()
    for i in range(90):
        t = i / 30
        d = kf.update((wrap_deg(170.0 + 30.0 * t), 0.0), t)
        assert -180.0 <= d.yaw < 180.0
    assert d.yaw == pytest.approx(wrap_deg(170.0 + 30.0 * 89 / 30), abs=0.5)


def test_extrapolation_wraps_the_yaw() -> None:
    assert Direction(175.0, 2.0, 20.0, -1.0, 1.0).at(1.5) == pytest.approx((-175.0, 1.5))
    assert Direction(-175.0, 0.0, -20.0, 0.0, 0.0).at(0.5) == pytest.approx((175.0, 0.0))
