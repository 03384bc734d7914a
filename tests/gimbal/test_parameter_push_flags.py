"""The parameter push's flags byte (section 2.3.4.9, Figure 15): bit 0 angles, bit 1 angle limits,
bit 2 stiffness; each bit may be 0 ("the pushed values are invalid"), all three at once included."""
from __future__ import annotations

import dataclasses

import pytest

from gimbal.messages.telemetry import ParameterPush

FULL = ParameterPush(7, 100, -20, 300, -1790, 25, -555, 145, 55, 179, 178, 30, 29, 10, 20, 30)


@pytest.mark.parametrize("flags,angles,limits,stiffness", [
    (0x00, False, False, False),
    (0x01, True, False, False),
    (0x02, False, True, False),
    (0x04, False, False, True),
    (0x07, True, True, True),
])
def test_each_flag_bit_validates_its_own_group(flags: int, angles: bool, limits: bool, stiffness: bool) -> None:
    """A full push is read per group as its flag bit says, and every such flags byte is in range."""
    push = dataclasses.replace(FULL, ctrl_byte=flags)
    push.validate()
    assert (push.angles_valid, push.joint_valid, push.limits_valid, push.stiffness_valid) \
        == (angles, angles, limits, stiffness)
