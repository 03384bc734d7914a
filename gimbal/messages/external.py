"""External controllers (0x0E/0x0A: joystick, dial) and the focus motor (0x12)."""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from gimbal.messages.base import GIMBAL_CMD_SET, register
from gimbal.messages.kinds import Command, HostPush, Reply
from gimbal.messages.limits import DIAL_RANGE, FOCUS_POSITION_RANGE, JOYSTICK_RANGE

CONTROLLER_UNKNOWN = 0x00
CONTROLLER_JOYSTICK = 0x01
CONTROLLER_DIAL = 0x02

FOCUS_POSITION_CONTROL = 0x01
FOCUS_CALIBRATION = 0x02
FOCUS_POSITION_QUERY = 0x15
FOCUS_MOTOR = 0x00
FOCUS_CAL_NONE, FOCUS_CAL_AUTO, FOCUS_CAL_MANUAL = 0x00, 0x01, 0x02
FOCUS_CAL_SET_MIN, FOCUS_CAL_SET_MAX, FOCUS_CAL_STOP = 0x04, 0x05, 0x06
FOCUS_CALIBRATION_COMMANDS = {FOCUS_CAL_NONE: "none", FOCUS_CAL_AUTO: "auto", FOCUS_CAL_MANUAL: "manual",
                              FOCUS_CAL_SET_MIN: "set_min", FOCUS_CAL_SET_MAX: "set_max",
                              FOCUS_CAL_STOP: "stop"}
FOCUS_NOT_CALIBRATED, FOCUS_CALIBRATING, FOCUS_CALIBRATED = 0x01, 0x02, 0x03
FOCUS_CALIBRATION_STATES = {FOCUS_NOT_CALIBRATED: "not calibrated", FOCUS_CALIBRATING: "calibrating",
                            FOCUS_CALIBRATED: "calibrated"}


@register
@dataclass
class JoystickPush(HostPush):
    """Joystick speeds, each (adc - middle) / range × 15000; by default Y -> pitch, X -> yaw."""

    CMD_SET: ClassVar[int] = GIMBAL_CMD_SET
    CMD_ID: ClassVar[int] = 0x0A
    NAME: ClassVar[str] = "joystick_push"
    FORMAT: ClassVar[str] = "Bhhh"
    RANGES: ClassVar = {"pitch_speed": JOYSTICK_RANGE, "roll_speed": JOYSTICK_RANGE,
                        "yaw_speed": JOYSTICK_RANGE}
    CHOICES: ClassVar = {"device_type": frozenset({CONTROLLER_JOYSTICK})}
    device_type: int = CONTROLLER_JOYSTICK
    pitch_speed: int = 0
    roll_speed: int = 0
    yaw_speed: int = 0

    @classmethod
    def matches(cls, payload: bytes) -> bool:
        return bool(payload) and payload[0] == CONTROLLER_JOYSTICK


@register
@dataclass
class DialPush(HostPush):
    """A dial's speed, for focus, exposure or other parameters the gimbal maps it to."""

    CMD_SET: ClassVar[int] = GIMBAL_CMD_SET
    CMD_ID: ClassVar[int] = 0x0A
    NAME: ClassVar[str] = "dial_push"
    FORMAT: ClassVar[str] = "Bh"
    RANGES: ClassVar = {"dial_speed": DIAL_RANGE}
    CHOICES: ClassVar = {"device_type": frozenset({CONTROLLER_DIAL})}
    device_type: int = CONTROLLER_DIAL
    dial_speed: int = 0

    @classmethod
    def matches(cls, payload: bytes) -> bool:
        return bool(payload) and payload[0] == CONTROLLER_DIAL


@register
@dataclass
class FocusPositionControl(HostPush):
    """Focus motor absolute position 0..4095, pushed at up to 100 Hz, unanswered."""

    CMD_SET: ClassVar[int] = GIMBAL_CMD_SET
    CMD_ID: ClassVar[int] = 0x12
    NAME: ClassVar[str] = "focus_position_control"
    FORMAT: ClassVar[str] = "BBBH"
    RANGES: ClassVar = {"position": FOCUS_POSITION_RANGE}
    CHOICES: ClassVar = {"sub_id": frozenset({FOCUS_POSITION_CONTROL}),
                         "control_type": frozenset({0x00}), "data_length": frozenset({0x02})}
    sub_id: int = FOCUS_POSITION_CONTROL
    control_type: int = 0x00
    data_length: int = 0x02
    position: int = 0

    @classmethod
    def matches(cls, payload: bytes) -> bool:
        return bool(payload) and payload[0] == FOCUS_POSITION_CONTROL


def _reply_sub_id_is(payload: bytes, sub_id: int) -> bool:
    return len(payload) >= 2 and payload[1] == sub_id


@register
@dataclass
class FocusCalibrationReply(Reply):
    """``result`` 0: done, 1: failed."""

    CMD_SET: ClassVar[int] = GIMBAL_CMD_SET
    CMD_ID: ClassVar[int] = 0x12
    NAME: ClassVar[str] = "focus_calibration_reply"
    FORMAT: ClassVar[str] = "BBBB"
    CHOICES: ClassVar = {"sub_id": frozenset({FOCUS_CALIBRATION}), "motor_type": frozenset({FOCUS_MOTOR}),
                         "result": frozenset({0x00, 0x01})}
    return_code: int = 0
    sub_id: int | None = FOCUS_CALIBRATION
    motor_type: int | None = FOCUS_MOTOR
    result: int | None = 0

    @classmethod
    def matches(cls, payload: bytes) -> bool:
        return _reply_sub_id_is(payload, FOCUS_CALIBRATION)


@register
@dataclass
class FocusCalibration(Command):
    """Start auto (1) or manual (2) calibration, set min (4) / max (5) travel, stop (6)."""

    CMD_SET: ClassVar[int] = GIMBAL_CMD_SET
    CMD_ID: ClassVar[int] = 0x12
    NAME: ClassVar[str] = "focus_calibration"
    FORMAT: ClassVar[str] = "BBB"
    CHOICES: ClassVar = {"sub_id": frozenset({FOCUS_CALIBRATION}), "motor_type": frozenset({FOCUS_MOTOR}),
                         "calibration_cmd": frozenset(FOCUS_CALIBRATION_COMMANDS)}
    REPLY: ClassVar = FocusCalibrationReply
    sub_id: int = FOCUS_CALIBRATION
    motor_type: int = FOCUS_MOTOR
    calibration_cmd: int = 0x01

    @classmethod
    def matches(cls, payload: bytes) -> bool:
        return bool(payload) and payload[0] == FOCUS_CALIBRATION


@register
@dataclass
class FocusPositionReply(Reply):
    """Calibration state (1 not calibrated, 2 calibrating, 3 calibrated) and position 0..4095."""

    CMD_SET: ClassVar[int] = GIMBAL_CMD_SET
    CMD_ID: ClassVar[int] = 0x12
    NAME: ClassVar[str] = "focus_position_reply"
    FORMAT: ClassVar[str] = "BBBBI"
    RANGES: ClassVar = {"position": FOCUS_POSITION_RANGE}
    CHOICES: ClassVar = {"sub_id": frozenset({FOCUS_POSITION_QUERY}), "motor_type": frozenset({FOCUS_MOTOR}),
                         "calibration_state": frozenset(FOCUS_CALIBRATION_STATES)}
    return_code: int = 0
    sub_id: int | None = FOCUS_POSITION_QUERY
    motor_type: int | None = FOCUS_MOTOR
    calibration_state: int | None = None
    position: int | None = None

    @classmethod
    def matches(cls, payload: bytes) -> bool:
        return _reply_sub_id_is(payload, FOCUS_POSITION_QUERY)


@register
@dataclass
class FocusPositionQuery(Command):
    """Read the focus motor's calibration state and current position."""

    CMD_SET: ClassVar[int] = GIMBAL_CMD_SET
    CMD_ID: ClassVar[int] = 0x12
    NAME: ClassVar[str] = "focus_position_query"
    FORMAT: ClassVar[str] = "BB"
    CHOICES: ClassVar = {"sub_id": frozenset({FOCUS_POSITION_QUERY}), "motor_type": frozenset({FOCUS_MOTOR})}
    REPLY: ClassVar = FocusPositionReply
    sub_id: int = FOCUS_POSITION_QUERY
    motor_type: int = FOCUS_MOTOR

    @classmethod
    def matches(cls, payload: bytes) -> bool:
        return bool(payload) and payload[0] == FOCUS_POSITION_QUERY
