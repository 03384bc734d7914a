"""Intermediate bases: who sends a message and whether it is answered."""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from gimbal.messages.base import Kind, Message, Sender


@dataclass
class Command(Message):
    """Host -> device; answered by ``REPLY`` when the document defines one."""

    KIND: ClassVar[Kind] = Kind.COMMAND
    SENDER: ClassVar[Sender] = Sender.HOST


@dataclass
class HostPush(Message):
    """Host -> device, never answered (joystick, dial, version, focus position)."""

    KIND: ClassVar[Kind] = Kind.PUSH
    SENDER: ClassVar[Sender] = Sender.HOST


@dataclass
class DevicePush(Message):
    """Device -> host, unsolicited (parameter push, calibration status)."""

    KIND: ClassVar[Kind] = Kind.PUSH
    SENDER: ClassVar[Sender] = Sender.DEVICE


@dataclass
class Reply(Message):
    """Device -> host answer; the first field is always ``return_code``. A NACK may carry the
    return code alone, so the other fields decode as None when absent."""

    KIND: ClassVar[Kind] = Kind.REPLY
    SENDER: ClassVar[Sender] = Sender.DEVICE
    PARTIAL: ClassVar[bool] = True

    @property
    def ok(self) -> bool:
        return getattr(self, "return_code") == 0


@dataclass
class ReturnCodeReply(Reply):
    """A reply that carries only the return code."""

    FORMAT: ClassVar[str] = "B"
    return_code: int = 0
