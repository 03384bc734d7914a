"""Live settings: ``retune`` applies new limits and gains from the next update on, without a jump."""
import dataclasses

import pytest

from pipelines.control.camera import CameraModel
from pipelines.control.controller import ControlConfig, make_controller
from tracker.runtime.estimate import TargetEstimate, TrackState

CAM = CameraModel(640, 360)


def estimate(t: float, x: float) -> TargetEstimate:
    return TargetEstimate((x - 20, 160, 40, 40), (0.0, 0.0), 0.9, TrackState.TRACKING, t, 0)


def drive(controller, start: int, frames: int, x: float = 600.0) -> list:
    return [controller.update(estimate(i / 30, x), (0.0, 0.0), i / 30) for i in range(start, start + frames)]


@pytest.mark.parametrize("name", ["pid", "p"])
def test_a_lower_speed_limit_holds_from_the_next_updates(name: str) -> None:
    """The pid controller clamps at once; the baseline slows within its acceleration limit."""
    controller = make_controller(name, camera=CAM)
    before = drive(controller, 0, 30)
    assert abs(before[-1].yaw_dps) > 40
    controller.retune(dataclasses.replace(controller.config, max_speed_dps=10.0))
    after = [abs(c.yaw_dps) for c in drive(controller, 30, 30)]
    assert all(b <= a + 1e-9 for a, b in zip([abs(before[-1].yaw_dps), *after], after))  # never faster
    assert all(v <= 10.0 + 1e-9 for v in after[10:])


def test_the_same_settings_change_nothing() -> None:
    retuned, twin = make_controller("pid", camera=CAM), make_controller("pid", camera=CAM)
    drive(retuned, 0, 20), drive(twin, 0, 20)
    retuned.retune(dataclasses.replace(retuned.config))
    assert [c.yaw_dps for c in drive(retuned, 20, 10)] == [c.yaw_dps for c in drive(twin, 20, 10)]


def test_new_gains_and_dead_band_reach_the_pid() -> None:
    controller = make_controller("pid", camera=CAM)
    controller.retune(dataclasses.replace(ControlConfig(), kp=3.0, ki=0.2, kd=0.1, deadband_deg=0.5))
    for pid in (controller._pid_yaw, controller._pid_pitch):
        assert (pid.kp, pid.ki, pid.kd, pid.deadband) == (3.0, 0.2, 0.1, 0.5)


def test_the_baseline_refuses_gains_it_does_not_have() -> None:
    controller = make_controller("p", camera=CAM)
    with pytest.raises(ValueError, match="kp, deadband_deg apply to the pid controller only"):
        controller.retune(dataclasses.replace(controller.config, kp=5.0, deadband_deg=1.0))
    assert controller.config == ControlConfig()
