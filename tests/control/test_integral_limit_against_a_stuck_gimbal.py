"""The PID's integral share of a setpoint is capped by ``integral_limit_dps``."""
from pipelines.control.camera import CameraModel
from pipelines.control.controller import ControlConfig, RateController
from tracker.estimate import TargetEstimate, TrackState

CAM = CameraModel(640, 360)


def test_a_gimbal_held_at_its_stop_does_not_wind_the_integral_past_its_limit() -> None:
    """The subject stays 3 deg right of a gimbal that cannot move: the error never closes, and the
    setpoint grows by the integral only up to ``integral_limit_dps`` over the proportional part."""
    cfg = ControlConfig(ki=4.0, integral_limit_dps=5.0)
    controller = RateController(CAM, cfg)
    x, _ = CAM.angles_to_pixel(3.0, 0.0)
    for i in range(150):
        t = i / 30
        estimate = TargetEstimate((x - 10.0, 170.0, 20.0, 20.0), (0.0, 0.0), 0.9, TrackState.TRACKING, t, i)
        command = controller.update(estimate, (0.0, 0.0), t)
        proportional = cfg.kp * (command.yaw_error_deg - cfg.deadband_deg)
        assert command.yaw_dps <= proportional + cfg.integral_limit_dps + 1e-6
    assert command.yaw_dps > proportional + 0.99 * cfg.integral_limit_dps  # it did reach the limit
