"""Commanded speeds never exceed ``max_speed_dps`` (speed control and joystick alike)."""
from __future__ import annotations

from collections import Counter

import pytest

from gimbal.messages import external, motion
from gimbal.sim import SimConfig
from gimbal.sim.model import GimbalModel


def test_speed_control_above_the_maximum_is_held_to_it() -> None:
    """200 °/s asked of a 100 °/s gimbal: it turns at 100 °/s (after the 720 °/s² ramp)."""
    model = GimbalModel(SimConfig(max_speed_dps=100.0), 0.0)
    assert model.handle(motion.SpeedControl(yaw_speed=2000, pitch_speed=-2000), 0.0).ok
    state = model.snapshot(0.3, Counter(), Counter())
    assert state.speeds[0] == pytest.approx(100.0) and state.speeds[2] == pytest.approx(-100.0)


def test_a_full_scale_joystick_beyond_the_maximum_is_held_to_it() -> None:
    """Joystick full scale 150 °/s on a 100 °/s gimbal: full deflection gives 100 °/s."""
    model = GimbalModel(SimConfig(max_speed_dps=100.0), 0.0)
    model.apply_push(external.JoystickPush(yaw_speed=external.JOYSTICK_RANGE[1]), 0.0)
    assert model.snapshot(0.4, Counter(), Counter()).speeds[0] == pytest.approx(100.0)
