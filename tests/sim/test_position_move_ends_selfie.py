"""A position move ends the selfie pose: the next selfie command turns yaw round again, not back to 0."""
from __future__ import annotations

from gimbal.messages import motion, settings
from gimbal.sim import SimConfig
from gimbal.sim.model import GimbalModel


def test_selfie_after_a_position_move_goes_to_the_selfie_yaw_again() -> None:
    """Selfie (yaw 179°, the default limit), position to yaw 30°, selfie again: yaw 179°, selfie set."""
    model = GimbalModel(SimConfig(), 0.0)
    assert model.handle(settings.RecenterSelfie(action=settings.SELFIE), 0.0).ok
    model.advance(2.0)  # 179° at 100 °/s
    assert model.joint()[0] == 179.0 and model.selfie
    assert model.handle(motion.PositionControl(yaw_angle=300, time_for_action=5), 2.0).ok
    model.advance(4.0)
    assert model.joint()[0] == 30.0 and not model.selfie
    assert model.handle(settings.RecenterSelfie(action=settings.SELFIE), 4.0).ok
    model.advance(6.0)
    assert model.joint()[0] == 179.0 and model.selfie
