"""Third-party camera commands (CmdSet 0x0D): actions (0x00) and record status (0x01)."""
from __future__ import annotations

from dataclasses import dataclass
from enum import IntEnum
from typing import ClassVar

from gimbal.messages.base import CAMERA_CMD_SET, register
from gimbal.messages.kinds import Command, Reply, ReturnCodeReply

QUERY_RECORDING = 0x01
NOT_RECORDING = 0x00
RECORDING = 0x02


class CameraActionCode(IntEnum):
    TAKE_PHOTO = 0x0001
    STOP_PHOTO = 0x0002
    START_RECORDING = 0x0003
    STOP_RECORDING = 0x0004
    CENTER_FOCUS = 0x0005
    END_CENTER_FOCUS = 0x000B


@register
@dataclass
class CameraActionReply(ReturnCodeReply):
    CMD_SET: ClassVar[int] = CAMERA_CMD_SET
    CMD_ID: ClassVar[int] = 0x00
    NAME: ClassVar[str] = "camera_action_reply"


@register
@dataclass
class CameraAction(Command):
    """Photo, record start/stop or centre focus on a camera controlled through the gimbal."""

    CMD_SET: ClassVar[int] = CAMERA_CMD_SET
    CMD_ID: ClassVar[int] = 0x00
    NAME: ClassVar[str] = "camera_action"
    FORMAT: ClassVar[str] = "H"
    CHOICES: ClassVar = {"action": frozenset(CameraActionCode)}
    REPLY: ClassVar = CameraActionReply
    action: int = CameraActionCode.TAKE_PHOTO


@register
@dataclass
class CameraStatusReply(Reply):
    """``camera_status`` 0x00: not recording, 0x02: recording."""

    CMD_SET: ClassVar[int] = CAMERA_CMD_SET
    CMD_ID: ClassVar[int] = 0x01
    NAME: ClassVar[str] = "camera_status_reply"
    FORMAT: ClassVar[str] = "BB"
    CHOICES: ClassVar = {"camera_status": frozenset({NOT_RECORDING, RECORDING})}
    return_code: int = 0
    camera_status: int | None = None

    @property
    def recording(self) -> bool | None:
        return None if self.camera_status is None else self.camera_status == RECORDING


@register
@dataclass
class CameraStatusQuery(Command):
    CMD_SET: ClassVar[int] = CAMERA_CMD_SET
    CMD_ID: ClassVar[int] = 0x01
    NAME: ClassVar[str] = "camera_status_query"
    FORMAT: ClassVar[str] = "B"
    CHOICES: ClassVar = {"query": frozenset({QUERY_RECORDING})}
    REPLY: ClassVar = CameraStatusReply
    query: int = QUERY_RECORDING
