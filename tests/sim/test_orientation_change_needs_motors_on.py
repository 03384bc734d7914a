"""Work mode (0x0D) orientation changes are motion: refused with 0x02 while the motors are off."""
from __future__ import annotations

from gimbal.messages import settings, tlv_params
from gimbal.messages.tlv_params import motors_off
from gimbal.sim import SimConfig
from gimbal.sim.model import GimbalModel


def test_portrait_with_motors_off_fails_and_keeps_the_orientation() -> None:
    """Motors off: portrait (0x03) replies 0x02, orientation stays 0°; back on, it is accepted."""
    model = GimbalModel(SimConfig(), 0.0)
    assert model.handle(tlv_params.SetUserParams((motors_off(True),)), 0.0).ok
    assert model.handle(settings.SetWorkMode(orientation=0x03), 0.0).return_code == 0x02
    assert model.orientation == 0
    assert model.handle(settings.SetWorkMode(orientation=0x00), 0.0).ok  # no orientation change: fine
    assert model.handle(tlv_params.SetUserParams((motors_off(False),)), 0.1).ok
    assert model.handle(settings.SetWorkMode(orientation=0x03), 0.1).ok
    assert model.orientation == 90
