"""Speed control toward the negative side stops at the lower (min) limits, as it does at the max."""
from __future__ import annotations

from collections import Counter

from gimbal.messages import motion, settings
from gimbal.sim import SimConfig
from gimbal.sim.model import GimbalModel


def test_negative_pitch_speed_stops_at_the_user_pitch_min() -> None:
    """-100 °/s from -40° with pitch_min 45: held at -45°, at rest, not past the limit."""
    model = GimbalModel(SimConfig(initial_joint_deg=(0.0, 0.0, -40.0)), 0.0)
    limits = settings.SetAngleLimits(pitch_max=145, pitch_min=45, yaw_max=179, yaw_min=179,
                                     roll_max=30, roll_min=30)
    assert model.handle(limits, 0.0).ok
    assert model.handle(motion.SpeedControl(pitch_speed=-1000), 0.0).ok
    state = model.snapshot(0.3, Counter(), Counter())
    assert state.joint[2] == -45.0 and state.speeds[2] == 0.0


def test_negative_yaw_and_roll_speeds_stop_at_the_default_min_limits() -> None:
    """Default limits: yaw −179°, roll −30°; a 0.5 s command that would overshoot stops there."""
    model = GimbalModel(SimConfig(initial_joint_deg=(-170.0, -20.0, 0.0)), 0.0)
    assert model.handle(motion.SpeedControl(yaw_speed=-1000, roll_speed=-1000), 0.0).ok
    state = model.snapshot(0.4, Counter(), Counter())
    assert state.joint[:2] == (-179.0, -30.0)
    assert state.speeds[:2] == (0.0, 0.0)
