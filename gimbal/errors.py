"""The gimbal package's exceptions."""
from __future__ import annotations

from enum import IntEnum


class GimbalError(Exception):
    """Base of everything the gimbal package raises on purpose."""


class RangeError(GimbalError, ValueError):
    """A field value outside the document's range; raised before anything is sent."""


class PayloadError(GimbalError, ValueError):
    """A payload that does not parse as the message it claims to be."""


class UnknownMessageError(PayloadError):
    """A CmdSet/CmdID (or sub-command) the document does not define."""


class ReturnCode(IntEnum):
    """Return codes of document section 2.3.2."""

    OK = 0x00
    PARSE_ERROR = 0x01
    EXECUTION_FAILED = 0x02
    UNDEFINED_ERROR = 0xFF

    @property
    def meaning(self) -> str:
        return _RETURN_CODE_MEANINGS[self]


_RETURN_CODE_MEANINGS = {
    ReturnCode.OK: "command executed",
    ReturnCode.PARSE_ERROR: "command could not be parsed",
    ReturnCode.EXECUTION_FAILED: "command could not be executed",
    ReturnCode.UNDEFINED_ERROR: "undefined error",
}


def describe_return_code(code: int) -> str:
    """The document's meaning of ``code``, or a note that it is not one of them."""
    try:
        return ReturnCode(code).meaning
    except ValueError:
        return f"return code 0x{code:02X} not defined by the document"


class ReturnCodeError(GimbalError):
    """The device answered with a non-zero return code."""

    def __init__(self, command: str, return_code: int) -> None:
        super().__init__(f"{command}: device returned 0x{return_code:02X} "
                         f"({describe_return_code(return_code)})")
        self.command = command
        self.return_code = return_code


class GimbalTimeoutError(GimbalError, TimeoutError):
    """No reply within the timeout, after all retries."""


class BusError(GimbalError):
    """The CAN bus failed or went away."""


class SendError(BusError):
    """The bus refused to send a frame (e.g. a full transmit queue: ENOBUFS on socketcan)."""
