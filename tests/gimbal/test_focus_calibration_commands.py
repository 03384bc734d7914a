"""Focus motor calibration (0x0E/0x12 sub-ID 0x02, section 2.3.4.19, Figure 33): the calibration
command codes the document lists, by code and by the client's names; 0x03 is reserved."""
from __future__ import annotations

import pytest

from gimbal.client import FOCUS_CALIBRATIONS
from gimbal.errors import RangeError
from gimbal.messages.external import FocusCalibration

DOCUMENT_COMMANDS = {
    0x00: "none",  # 无控制
    0x01: "auto",  # 启动自动校准
    0x02: "manual",  # 启动手动校准
    0x04: "set-min",  # 设置校准最小行程点
    0x05: "set-max",  # 设置校准最大行程点
    0x06: "stop",  # 停止校准
}


@pytest.mark.parametrize("code", sorted(DOCUMENT_COMMANDS))
def test_every_documented_calibration_command_encodes(code: int) -> None:
    """Each code goes out as sub-ID 0x02, motor type 0x00, then the code; its name maps to it."""
    assert FocusCalibration(calibration_cmd=code).encode_payload() == bytes((0x02, 0x00, code))
    assert FOCUS_CALIBRATIONS[DOCUMENT_COMMANDS[code]] == code


@pytest.mark.parametrize("code", [0x03, 0x07, 0xFF])
def test_reserved_calibration_commands_are_refused(code: int) -> None:
    with pytest.raises(RangeError, match="calibration_cmd"):
        FocusCalibration(calibration_cmd=code).encode_payload()
