"""Parameter push control (0x0E/0x07), the parameter push (0x08) and module versions (0x09)."""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from gimbal.messages.base import GIMBAL_CMD_SET, register
from gimbal.messages.kinds import Command, DevicePush, HostPush, Reply, ReturnCodeReply
from gimbal.messages.limits import LIMIT_RANGES, STIFFNESS_RANGES
from gimbal.messages.motion import AxisDegrees

PUSH_NO_OPERATION = 0x00
PUSH_ENABLE = 0x01
PUSH_DISABLE = 0x02

FLAG_ANGLES_VALID = 0x01
FLAG_LIMITS_VALID = 0x02
FLAG_STIFFNESS_VALID = 0x04

DEVICE_ID_RESERVED = 0x00000000
DEVICE_ID_R_SDK = 0x00000001
DEVICE_ID_REMOTE_CONTROLLER = 0x00000002
DEVICE_ID_RANGE = (DEVICE_ID_RESERVED + 1, 0xFFFFFFFF)  # 2.3.3 Figure 6: 0x00000000 is reserved (保留)


@register
@dataclass
class PushControlReply(ReturnCodeReply):
    CMD_SET: ClassVar[int] = GIMBAL_CMD_SET
    CMD_ID: ClassVar[int] = 0x07
    NAME: ClassVar[str] = "push_control_reply"


@register
@dataclass
class PushControl(Command):
    """Enable (1) or disable (2) the parameter push."""

    CMD_SET: ClassVar[int] = GIMBAL_CMD_SET
    CMD_ID: ClassVar[int] = 0x07
    NAME: ClassVar[str] = "push_control"
    FORMAT: ClassVar[str] = "B"
    CHOICES: ClassVar = {"ctrl_byte": frozenset({PUSH_NO_OPERATION, PUSH_ENABLE, PUSH_DISABLE})}
    REPLY: ClassVar = PushControlReply
    ctrl_byte: int = PUSH_ENABLE


@register
@dataclass
class ParameterPush(DevicePush):
    """Attitude, joint angles, limits and stiffness, pushed by the gimbal once enabled.

    The first byte is a flags byte (the document calls it ctrl_byte), not a return code. The
    document spells the joint fields ``*_joint_agnle``; they are named ``*_joint_angle`` here.
    Shorter pushes seen on real firmware decode with the missing fields as None.
    """

    CMD_SET: ClassVar[int] = GIMBAL_CMD_SET
    CMD_ID: ClassVar[int] = 0x08
    NAME: ClassVar[str] = "parameter_push"
    FORMAT: ClassVar[str] = "BhhhhhhBBBBBBBBB"
    RANGES: ClassVar = {"ctrl_byte": (0, 0x07), **LIMIT_RANGES, **STIFFNESS_RANGES}
    PARTIAL: ClassVar[bool] = True
    ctrl_byte: int = FLAG_ANGLES_VALID | FLAG_LIMITS_VALID | FLAG_STIFFNESS_VALID
    yaw_angle: int | None = None
    roll_angle: int | None = None
    pitch_angle: int | None = None
    yaw_joint_angle: int | None = None
    roll_joint_angle: int | None = None
    pitch_joint_angle: int | None = None
    pitch_max: int | None = None
    pitch_min: int | None = None
    yaw_max: int | None = None
    yaw_min: int | None = None
    roll_max: int | None = None
    roll_min: int | None = None
    pitch_stiffness: int | None = None
    yaw_stiffness: int | None = None
    roll_stiffness: int | None = None

    @property
    def angles_valid(self) -> bool:
        """The flag says the angles are valid and the attitude is present (a short push may end
        there, before the joint angles: see ``joint_valid``)."""
        return bool(self.ctrl_byte & FLAG_ANGLES_VALID) and self.pitch_angle is not None

    @property
    def joint_valid(self) -> bool:
        """``angles_valid`` and the joint angles are present too."""
        return self.angles_valid and self.pitch_joint_angle is not None

    @property
    def attitude(self) -> AxisDegrees | None:
        """The attitude in degrees when ``angles_valid``, else None."""
        if not self.angles_valid:
            return None
        return AxisDegrees.from_raw(self.yaw_angle, self.roll_angle, self.pitch_angle)  # type: ignore[arg-type]

    @property
    def joint(self) -> AxisDegrees | None:
        """The joint angles in degrees when ``joint_valid``, else None."""
        if not self.joint_valid:
            return None
        return AxisDegrees.from_raw(self.yaw_joint_angle, self.roll_joint_angle,  # type: ignore[arg-type]
                                    self.pitch_joint_angle)

    @property
    def limits_valid(self) -> bool:
        return bool(self.ctrl_byte & FLAG_LIMITS_VALID) and self.roll_min is not None

    @property
    def stiffness_valid(self) -> bool:
        return bool(self.ctrl_byte & FLAG_STIFFNESS_VALID) and self.roll_stiffness is not None


@register
@dataclass
class VersionReply(Reply):
    """``version`` 0xAABBCCDD means AA.BB.CC.DD."""

    CMD_SET: ClassVar[int] = GIMBAL_CMD_SET
    CMD_ID: ClassVar[int] = 0x09
    NAME: ClassVar[str] = "version_reply"
    FORMAT: ClassVar[str] = "BII"
    return_code: int = 0
    device_id: int | None = None
    version: int | None = None

    @property
    def version_text(self) -> str | None:
        return None if self.version is None else format_version(self.version)


@register
@dataclass
class VersionQuery(Command):
    """Ask for a module's version by device id (1: DJI R SDK)."""

    CMD_SET: ClassVar[int] = GIMBAL_CMD_SET
    CMD_ID: ClassVar[int] = 0x09
    NAME: ClassVar[str] = "version_query"
    FORMAT: ClassVar[str] = "I"
    RANGES: ClassVar = {"device_id": DEVICE_ID_RANGE}
    REPLY: ClassVar = VersionReply
    device_id: int = DEVICE_ID_R_SDK

    @classmethod
    def matches(cls, payload: bytes) -> bool:
        return len(payload) < 8

    def reply_is_mine(self, reply_payload: bytes) -> bool:
        """The reply names the device whose version it carries (2.3.4.10, 设备 ID at byte 1): a
        reply naming another answers another query. A NACK may name none (code alone, or 0,
        reserved by 2.3.3)."""
        if len(reply_payload) < 5:
            return True
        named = int.from_bytes(reply_payload[1:5], "little")
        return named == self.device_id or (reply_payload[0] != 0 and named == DEVICE_ID_RESERVED)


@register
@dataclass
class VersionPush(HostPush):
    """An external device announcing its own version to the gimbal, at 1 Hz, unanswered."""

    CMD_SET: ClassVar[int] = GIMBAL_CMD_SET
    CMD_ID: ClassVar[int] = 0x09
    NAME: ClassVar[str] = "version_push"
    FORMAT: ClassVar[str] = "II"
    RANGES: ClassVar = {"device_id": DEVICE_ID_RANGE}
    device_id: int = DEVICE_ID_R_SDK
    version: int = 0

    @classmethod
    def matches(cls, payload: bytes) -> bool:
        return len(payload) >= 8


def format_version(version: int) -> str:
    """0xAABBCCDD -> 'AA.BB.CC.DD', the document's notation (each byte as two hex digits)."""
    return ".".join(f"{(version >> shift) & 0xFF:02X}" for shift in (24, 16, 8, 0))
