"""Set work mode (0x0E/0x0D, section 2.3.4.14, Figure 26): work mode 0xFE (keep) and the seven
landscape/portrait codes the document lists, each accepted; anything else refused."""
from __future__ import annotations

import pytest

from gimbal.client import ORIENTATIONS
from gimbal.errors import RangeError
from gimbal.messages.settings import SetWorkMode

DOCUMENT_ORIENTATIONS = {
    0x00: "keep",  # 不切换横竖拍模式
    0x01: "landscape",  # 绕 X 轴旋转 0° 的横拍
    0x02: "landscape-flipped",  # 绕 X 轴旋转 180° 的横拍
    0x03: "portrait",  # 绕 X 轴旋转 90° 的竖拍
    0x04: "portrait-flipped",  # 绕 X 轴旋转 -90° 的竖拍
    0x05: "toggle",  # 横拍与竖拍互换
    0xFF: "default",  # 恢复默认模式
}


@pytest.mark.parametrize("code", sorted(DOCUMENT_ORIENTATIONS))
def test_every_documented_orientation_encodes(code: int) -> None:
    """Each code goes out as ``FE code``, and the client's name for it maps to that code."""
    assert SetWorkMode(orientation=code).encode_payload() == bytes((0xFE, code))
    assert ORIENTATIONS[DOCUMENT_ORIENTATIONS[code]] == code


@pytest.mark.parametrize("field,value", [("orientation", 0x06), ("orientation", 0xFE),
                                         ("work_mode", 0x00), ("work_mode", 0xFF)])
def test_values_the_document_does_not_list_are_refused(field: str, value: int) -> None:
    """Only 0xFE is defined for the work mode; orientations stop at 0x05 and 0xFF."""
    with pytest.raises(RangeError, match=field):
        SetWorkMode(**{field: value}).encode_payload()
