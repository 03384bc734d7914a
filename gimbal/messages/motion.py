"""Position control (0x0E/0x00), speed control (0x01) and angle read-out (0x02)."""
from __future__ import annotations

import math
import numbers
from dataclasses import dataclass
from typing import ClassVar, NamedTuple

from gimbal.errors import RangeError
from gimbal.messages.base import GIMBAL_CMD_SET, register
from gimbal.messages.kinds import Command, Reply, ReturnCodeReply
from gimbal.messages.limits import (PITCH_ANGLE_RANGE, ROLL_ANGLE_RANGE, SPEED_RANGE, TENTHS, TIME_RANGE,
                                    YAW_ANGLE_RANGE)
from gimbal.values import shown

DECI_DEGREE = (0.1, "°")
DECI_DEGREE_PER_S = (0.1, "°/s")
DECI_SECOND = (0.1, " s")

POSITION_ABSOLUTE = 0x01
POSITION_YAW_INVALID = 0x02
POSITION_ROLL_INVALID = 0x04
POSITION_PITCH_INVALID = 0x08
SPEED_TAKE_CONTROL = 0x80  # bit 7: 1 take, 0 release speed control
SPEED_IGNORE_FOCAL_LENGTH = 0x08  # bit 3: speed does not depend on the camera's focal length
SPEED_HOLD = SPEED_TAKE_CONTROL | SPEED_IGNORE_FOCAL_LENGTH  # 0x88: in control
SPEED_RELEASE = SPEED_IGNORE_FOCAL_LENGTH  # 0x08: bit 7 clear, control released

ANGLES_NONE = 0x00
ANGLES_ATTITUDE = 0x01
ANGLES_JOINT = 0x02

AXES = ("yaw", "roll", "pitch")  # the axis order of position, speed and angle messages
POSITION_INVALID = {"yaw": POSITION_YAW_INVALID, "roll": POSITION_ROLL_INVALID,
                    "pitch": POSITION_PITCH_INVALID}  # ctrl_byte bit that leaves the axis alone


def finite_number(value: float, name: str) -> float:
    """``value`` as a float: any real number but a bool (numpy's too); ``RangeError`` otherwise."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise RangeError(f"{name}={shown(value)} is not a number")
    if not math.isfinite(value):
        raise RangeError(f"{name}={shown(value)} is not a finite number")
    return float(value)


def to_raw(value: float, name: str) -> int:
    """Degrees (or °/s, or s) to the wire's 0.1 units, rounded to the nearest unit; a number too
    large for them (1e308 × 10 is infinite) is a ``RangeError`` like any other out of range."""
    scaled = finite_number(value, name) * TENTHS
    if not math.isfinite(scaled):
        raise RangeError(f"{name}={shown(value)} is outside any range the document gives")
    return round(scaled)


def from_raw(raw: int) -> float:
    """The wire's 0.1 units to degrees (or °/s, or s)."""
    return raw / TENTHS


class AxisDegrees(NamedTuple):
    """Three angles in degrees, in the document's axis order: what a reply or push carries in
    0.1° units, converted once here so that no reader converts raw units itself."""

    yaw: float
    roll: float
    pitch: float

    @classmethod
    def from_raw(cls, yaw: int, roll: int, pitch: int) -> AxisDegrees:
        return cls(from_raw(yaw), from_raw(roll), from_raw(pitch))


@register
@dataclass
class PositionControlReply(ReturnCodeReply):
    CMD_SET: ClassVar[int] = GIMBAL_CMD_SET
    CMD_ID: ClassVar[int] = 0x00
    NAME: ClassVar[str] = "position_control_reply"


@register
@dataclass
class PositionControl(Command):
    """Move to an angle (absolute or relative) in ``time_for_action`` × 0.1 s."""

    CMD_SET: ClassVar[int] = GIMBAL_CMD_SET
    CMD_ID: ClassVar[int] = 0x00
    NAME: ClassVar[str] = "position_control"
    FORMAT: ClassVar[str] = "hhhBB"
    RANGES: ClassVar = {"yaw_angle": YAW_ANGLE_RANGE, "roll_angle": ROLL_ANGLE_RANGE,
                        "pitch_angle": PITCH_ANGLE_RANGE, "ctrl_byte": (0, 0x0F),
                        "time_for_action": TIME_RANGE}
    UNITS: ClassVar = {"yaw_angle": DECI_DEGREE, "roll_angle": DECI_DEGREE, "pitch_angle": DECI_DEGREE,
                       "time_for_action": DECI_SECOND}
    REPLY: ClassVar = PositionControlReply
    yaw_angle: int = 0
    roll_angle: int = 0
    pitch_angle: int = 0
    ctrl_byte: int = POSITION_ABSOLUTE
    time_for_action: int = 20


@register
@dataclass
class SpeedControlReply(ReturnCodeReply):
    CMD_SET: ClassVar[int] = GIMBAL_CMD_SET
    CMD_ID: ClassVar[int] = 0x01
    NAME: ClassVar[str] = "speed_control_reply"


@register
@dataclass
class SpeedControl(Command):
    """Rotate at a speed for 0.5 s (resend to keep moving); bit 7 of ctrl_byte takes control."""

    CMD_SET: ClassVar[int] = GIMBAL_CMD_SET
    CMD_ID: ClassVar[int] = 0x01
    NAME: ClassVar[str] = "speed_control"
    FORMAT: ClassVar[str] = "hhhB"
    RANGES: ClassVar = {"yaw_speed": SPEED_RANGE, "roll_speed": SPEED_RANGE, "pitch_speed": SPEED_RANGE}
    UNITS: ClassVar = {"yaw_speed": DECI_DEGREE_PER_S, "roll_speed": DECI_DEGREE_PER_S,
                       "pitch_speed": DECI_DEGREE_PER_S}
    CHOICES: ClassVar = {"ctrl_byte": frozenset({0x00, 0x08, 0x80, 0x88})}  # reserved bits are 0
    REPLY: ClassVar = SpeedControlReply
    yaw_speed: int = 0
    roll_speed: int = 0
    pitch_speed: int = 0
    ctrl_byte: int = SPEED_TAKE_CONTROL | SPEED_IGNORE_FOCAL_LENGTH


@register
@dataclass
class AnglesReply(Reply):
    """``data_type`` 1: attitude angles, 2: joint angles, 0: not ready."""

    CMD_SET: ClassVar[int] = GIMBAL_CMD_SET
    CMD_ID: ClassVar[int] = 0x02
    NAME: ClassVar[str] = "get_angles_reply"
    FORMAT: ClassVar[str] = "BBhhh"
    CHOICES: ClassVar = {"data_type": frozenset({ANGLES_NONE, ANGLES_ATTITUDE, ANGLES_JOINT})}
    return_code: int = 0
    data_type: int | None = None
    yaw: int | None = None
    roll: int | None = None
    pitch: int | None = None

    @property
    def degrees(self) -> AxisDegrees | None:
        """The angles in degrees; None when the reply stops short of them."""
        if self.yaw is None or self.roll is None or self.pitch is None:
            return None
        return AxisDegrees.from_raw(self.yaw, self.roll, self.pitch)


@register
@dataclass
class GetAngles(Command):
    """Ask for the attitude (``ctrl_byte`` 1) or joint (2) angles."""

    CMD_SET: ClassVar[int] = GIMBAL_CMD_SET
    CMD_ID: ClassVar[int] = 0x02
    NAME: ClassVar[str] = "get_angles"
    FORMAT: ClassVar[str] = "B"
    CHOICES: ClassVar = {"ctrl_byte": frozenset({ANGLES_NONE, ANGLES_ATTITUDE, ANGLES_JOINT})}
    REPLY: ClassVar = AnglesReply
    ctrl_byte: int = ANGLES_ATTITUDE
