"""A target found again after the controller stopped is filtered and controlled afresh."""
from pipelines.control.camera import CameraModel
from pipelines.control.controller import ControlConfig, RateController
from tracker.estimate import TargetEstimate, TrackState

CAM = CameraModel(640, 360)


def _seen(x: float, t: float, index: int) -> TargetEstimate:
    return TargetEstimate((x - 10.0, 170.0, 20.0, 20.0), (0.0, 0.0), 0.9, TrackState.TRACKING, t, index)


def test_a_still_centred_target_found_after_a_loss_is_not_chased_with_the_old_motion() -> None:
    """A subject panning at ~45 deg/s is lost for 1 s (over ``stop_within_s``), then found standing
    still at the centre: no speed of the old pan (filter velocity, integral) may reach the gimbal."""
    controller = RateController(CAM)
    assert ControlConfig().stop_within_s < 1.0
    for i in range(30):
        controller.update(_seen(320.0 + 8.0 * i, i / 30, i), (0.0, 0.0), i / 30)
    for i in range(30, 60):
        assert controller.update(None, None, i / 30).mode in {"hold", "ramp", "idle"}
    for i in range(60, 75):
        command = controller.update(_seen(320.0, i / 30, i), (0.0, 0.0), i / 30)
        assert command.mode == "track"
        assert abs(command.yaw_dps) < 0.05 and abs(command.pitch_dps) < 0.05
