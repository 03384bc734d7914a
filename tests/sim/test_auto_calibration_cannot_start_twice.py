"""Auto-calibration (0x0F) started while it runs fails with 0x02 and does not restart it."""
from __future__ import annotations

from gimbal.messages import tlv_params
from gimbal.messages.tlv_params import CALIBRATION_DONE, CALIBRATION_RUNNING, AutoCalibration, autotune
from gimbal.sim import SimConfig
from gimbal.sim.model import GimbalModel


def test_a_second_start_while_running_fails_and_keeps_the_first_schedule() -> None:
    """Started at 0 s (3 s run), started again at 1 s: 0x02, still done at 3 s, not 4 s."""
    model = GimbalModel(SimConfig(calibration_s=3.0), 0.0)
    assert model.handle(AutoCalibration((autotune(True),)), 0.0).ok
    reply = model.handle(AutoCalibration((autotune(True),)), 1.0)
    assert reply.return_code == 0x02
    model.advance(2.0)
    assert model.calibration[0] == CALIBRATION_RUNNING and model.calibration[1] >= 60
    pushes = model.advance(3.05)
    assert model.calibration == (CALIBRATION_DONE, 100)
    assert any(isinstance(m, tlv_params.CalibrationStatusPush) for m in pushes)


def test_start_after_done_is_accepted() -> None:
    """Only a running calibration blocks a start: once done, a new one may begin."""
    model = GimbalModel(SimConfig(calibration_s=1.0), 0.0)
    assert model.handle(AutoCalibration((autotune(True),)), 0.0).ok
    model.advance(1.5)
    assert model.handle(AutoCalibration((autotune(True),)), 1.5).ok
    model.advance(1.6)
    assert model.calibration[0] == CALIBRATION_RUNNING
