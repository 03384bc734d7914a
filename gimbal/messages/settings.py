"""Angle limits (0x0E/0x03, 0x04), motor stiffness (0x05, 0x06), work mode (0x0D), recenter,
selfie and follow mode (0x0E) and the ActiveTrack toggle (0x11)."""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from gimbal.messages.base import GIMBAL_CMD_SET, register
from gimbal.messages.kinds import Command, Reply, ReturnCodeReply
from gimbal.messages.limits import LIMIT_RANGES, STIFFNESS_RANGES
NO_OPERATION = 0x00
DO_OPERATION = 0x01
_NOOP_OR_DO = {"ctrl_byte": frozenset({NO_OPERATION, DO_OPERATION})}

KEEP_MODE = 0xFE
ORIENTATIONS = frozenset({0x00, 0x01, 0x02, 0x03, 0x04, 0x05, 0xFF})
RECENTER = 0x01
SELFIE = 0x02
FOLLOW_LOCK = 0x00
FOLLOW_YAW = 0x02
FOLLOW_FPV = 0x03  # the document's "运动模式" (sport/FPV)
ACTIVETRACK_TOGGLE = 0x03


@register
@dataclass
class SetAngleLimitsReply(ReturnCodeReply):
    CMD_SET: ClassVar[int] = GIMBAL_CMD_SET
    CMD_ID: ClassVar[int] = 0x03
    NAME: ClassVar[str] = "set_angle_limits_reply"


@register
@dataclass
class SetAngleLimits(Command):
    """User angle limits in whole degrees (min values are magnitudes below zero)."""

    CMD_SET: ClassVar[int] = GIMBAL_CMD_SET
    CMD_ID: ClassVar[int] = 0x03
    NAME: ClassVar[str] = "set_angle_limits"
    FORMAT: ClassVar[str] = "BBBBBBB"
    RANGES: ClassVar = LIMIT_RANGES
    CHOICES: ClassVar = _NOOP_OR_DO
    REPLY: ClassVar = SetAngleLimitsReply
    ctrl_byte: int = DO_OPERATION
    pitch_max: int = 145
    pitch_min: int = 55
    yaw_max: int = 179
    yaw_min: int = 179
    roll_max: int = 30
    roll_min: int = 30


@register
@dataclass
class AngleLimitsReply(Reply):
    CMD_SET: ClassVar[int] = GIMBAL_CMD_SET
    CMD_ID: ClassVar[int] = 0x04
    NAME: ClassVar[str] = "get_angle_limits_reply"
    FORMAT: ClassVar[str] = "BBBBBBB"
    RANGES: ClassVar = LIMIT_RANGES
    return_code: int = 0
    pitch_max: int | None = None
    pitch_min: int | None = None
    yaw_max: int | None = None
    yaw_min: int | None = None
    roll_max: int | None = None
    roll_min: int | None = None


@register
@dataclass
class GetAngleLimits(Command):
    CMD_SET: ClassVar[int] = GIMBAL_CMD_SET
    CMD_ID: ClassVar[int] = 0x04
    NAME: ClassVar[str] = "get_angle_limits"
    FORMAT: ClassVar[str] = "B"
    CHOICES: ClassVar = _NOOP_OR_DO
    REPLY: ClassVar = AngleLimitsReply
    ctrl_byte: int = DO_OPERATION


@register
@dataclass
class SetMotorStiffnessReply(ReturnCodeReply):
    CMD_SET: ClassVar[int] = GIMBAL_CMD_SET
    CMD_ID: ClassVar[int] = 0x05
    NAME: ClassVar[str] = "set_motor_stiffness_reply"


@register
@dataclass
class SetMotorStiffness(Command):
    """Motor stiffness 0..100 per axis; the set order is pitch, roll, yaw (the document's)."""

    CMD_SET: ClassVar[int] = GIMBAL_CMD_SET
    CMD_ID: ClassVar[int] = 0x05
    NAME: ClassVar[str] = "set_motor_stiffness"
    FORMAT: ClassVar[str] = "BBBB"
    RANGES: ClassVar = STIFFNESS_RANGES
    CHOICES: ClassVar = _NOOP_OR_DO
    REPLY: ClassVar = SetMotorStiffnessReply
    ctrl_byte: int = DO_OPERATION
    pitch_stiffness: int = 50
    roll_stiffness: int = 50
    yaw_stiffness: int = 50


@register
@dataclass
class MotorStiffnessReply(Reply):
    """The get reply orders the axes pitch, yaw, roll (unlike the set command)."""

    CMD_SET: ClassVar[int] = GIMBAL_CMD_SET
    CMD_ID: ClassVar[int] = 0x06
    NAME: ClassVar[str] = "get_motor_stiffness_reply"
    FORMAT: ClassVar[str] = "BBBB"
    RANGES: ClassVar = STIFFNESS_RANGES
    return_code: int = 0
    pitch_stiffness: int | None = None
    yaw_stiffness: int | None = None
    roll_stiffness: int | None = None


@register
@dataclass
class GetMotorStiffness(Command):
    CMD_SET: ClassVar[int] = GIMBAL_CMD_SET
    CMD_ID: ClassVar[int] = 0x06
    NAME: ClassVar[str] = "get_motor_stiffness"
    FORMAT: ClassVar[str] = "B"
    CHOICES: ClassVar = _NOOP_OR_DO
    REPLY: ClassVar = MotorStiffnessReply
    ctrl_byte: int = DO_OPERATION


@register
@dataclass
class SetWorkModeReply(ReturnCodeReply):
    CMD_SET: ClassVar[int] = GIMBAL_CMD_SET
    CMD_ID: ClassVar[int] = 0x0D
    NAME: ClassVar[str] = "set_work_mode_reply"


@register
@dataclass
class SetWorkMode(Command):
    """Landscape/portrait orientation; the document defines only 0xFE (keep) for the mode."""

    CMD_SET: ClassVar[int] = GIMBAL_CMD_SET
    CMD_ID: ClassVar[int] = 0x0D
    NAME: ClassVar[str] = "set_work_mode"
    FORMAT: ClassVar[str] = "BB"
    CHOICES: ClassVar = {"work_mode": frozenset({KEEP_MODE}), "orientation": ORIENTATIONS}
    REPLY: ClassVar = SetWorkModeReply
    work_mode: int = KEEP_MODE
    orientation: int = 0x00


@register
@dataclass
class RecenterFollowReply(ReturnCodeReply):
    """The answer to both recenter/selfie and follow-mode commands (they share CmdID 0x0E)."""

    CMD_SET: ClassVar[int] = GIMBAL_CMD_SET
    CMD_ID: ClassVar[int] = 0x0E
    NAME: ClassVar[str] = "recenter_follow_reply"


@register
@dataclass
class RecenterSelfie(Command):
    """Recenter once (``action`` 1) or selfie (2); ``work_mode`` is always 0xFE."""

    CMD_SET: ClassVar[int] = GIMBAL_CMD_SET
    CMD_ID: ClassVar[int] = 0x0E
    NAME: ClassVar[str] = "recenter_selfie"
    FORMAT: ClassVar[str] = "BB"
    CHOICES: ClassVar = {"work_mode": frozenset({KEEP_MODE}), "action": frozenset({RECENTER, SELFIE})}
    REPLY: ClassVar = RecenterFollowReply
    work_mode: int = KEEP_MODE
    action: int = RECENTER

    @classmethod
    def matches(cls, payload: bytes) -> bool:
        return bool(payload) and payload[0] == KEEP_MODE


@register
@dataclass
class SetFollowMode(Command):
    """Lock (0x00), yaw follow (0x02) or FPV/sport (0x03); ``action`` must be 0."""

    CMD_SET: ClassVar[int] = GIMBAL_CMD_SET
    CMD_ID: ClassVar[int] = 0x0E
    NAME: ClassVar[str] = "set_follow_mode"
    FORMAT: ClassVar[str] = "BB"
    CHOICES: ClassVar = {"work_mode": frozenset({FOLLOW_LOCK, FOLLOW_YAW, FOLLOW_FPV}),
                         "action": frozenset({0x00})}
    REPLY: ClassVar = RecenterFollowReply
    work_mode: int = FOLLOW_YAW
    action: int = 0x00

    @classmethod
    def matches(cls, payload: bytes) -> bool:
        return bool(payload) and payload[0] != KEEP_MODE


@register
@dataclass
class ActiveTrackReply(ReturnCodeReply):
    """The document shows no reply layout for 0x11; firmware that answers sends a return code."""

    CMD_SET: ClassVar[int] = GIMBAL_CMD_SET
    CMD_ID: ClassVar[int] = 0x11
    NAME: ClassVar[str] = "activetrack_reply"


@register
@dataclass
class ActiveTrack(Command):
    """Toggle ActiveTrack (smart follow) on or off."""

    CMD_SET: ClassVar[int] = GIMBAL_CMD_SET
    CMD_ID: ClassVar[int] = 0x11
    NAME: ClassVar[str] = "activetrack"
    FORMAT: ClassVar[str] = "B"
    CHOICES: ClassVar = {"action": frozenset({ACTIVETRACK_TOGGLE})}
    REPLY: ClassVar = ActiveTrackReply
    action: int = ACTIVETRACK_TOGGLE
