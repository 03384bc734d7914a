"""What the P baseline's setpoints report besides the speeds: signed errors and latency."""
import pytest

from pipelines.control.camera import CameraModel
from pipelines.control.controller import ProportionalController
from tracker.estimate import TargetEstimate, TrackState

CAM = CameraModel(640, 360)


def test_errors_follow_the_cameras_angle_convention_and_latency_is_now_minus_capture() -> None:
    """A target up and to the right: yaw and pitch errors are the camera's angles of its centre
    (both positive), and the latency is the time since the frame's capture."""
    controller = ProportionalController(CAM)
    box = (390.0, 90.0, 20.0, 20.0)  # centre (400, 100): right of and above (320, 180)
    controller.update(TargetEstimate(box, (0.0, 0.0), 0.9, TrackState.TRACKING, 0.0, 0), None, 0.01)
    command = controller.update(TargetEstimate(box, (0.0, 0.0), 0.9, TrackState.TRACKING, 1 / 30, 1), None, 0.05)
    assert (command.yaw_error_deg, command.pitch_error_deg) == pytest.approx(CAM.pixel_to_angles(400.0, 100.0))
    assert command.pitch_error_deg > 0.0 and command.yaw_error_deg > 0.0
    assert command.yaw_dps > 0.0 and command.pitch_dps > 0.0
    assert command.latency_s == pytest.approx(0.05 - 1 / 30)
    assert command.stamp == pytest.approx(1 / 30)
