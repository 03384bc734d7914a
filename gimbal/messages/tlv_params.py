"""TLV-coded messages: user parameters (0x0E/0x0B get, 0x0C set) and auto-calibration
(0x0F set, 0x10 status push)."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar, Self

from gimbal.errors import PayloadError, RangeError
from gimbal.messages.base import GIMBAL_CMD_SET, Tlv, decode_tlvs, encode_tlvs, register
from gimbal.messages.kinds import Command, DevicePush, Reply

PARAM_TABLE = 0x00  # which parameter table (0..2)
FOLLOW_SPECIAL = 0x22  # bits 3..5: 0 three-axis, 1 two-axis, 2 roll 360, 3 3D roll 360
MOTOR_SPECIAL = 0x23  # bit 0: motors off
USER_PARAM_IDS = {PARAM_TABLE: "param_table", FOLLOW_SPECIAL: "roll360_mode", MOTOR_SPECIAL: "motors_off"}
ROLL360_MODES = {0: "three_axis", 1: "two_axis", 2: "roll360", 3: "3d_roll360"}

AUTOTUNE = 0x00  # calibration TLV: bit 0 start/stop, bits 7..1 type (0 default, 1 single pose)
AUTOTUNE_TYPES = {0: "default", 1: "single_pose"}
CALIBRATION_IDLE, CALIBRATION_RUNNING, CALIBRATION_DONE, CALIBRATION_ERROR = 0, 1, 2, 3
CALIBRATION_STATES = {CALIBRATION_IDLE: "idle", CALIBRATION_RUNNING: "running", CALIBRATION_DONE: "done",
                      CALIBRATION_ERROR: "error"}
CALIBRATION_STATUS_LENGTH = 6


def param_table(table: int) -> Tlv:
    if table not in range(3):
        raise RangeError(f"param_table={table} is outside 0..2")
    return Tlv(PARAM_TABLE, bytes((table,)))


def roll360_mode(mode: int) -> Tlv:
    if mode not in ROLL360_MODES:
        raise RangeError(f"roll360 mode {mode} is not one of {sorted(ROLL360_MODES)}")
    return Tlv(FOLLOW_SPECIAL, bytes((mode << 3,)))


def motors_off(off: bool) -> Tlv:
    return Tlv(MOTOR_SPECIAL, bytes((int(off),)))


def autotune(start: bool, tune_type: int = 1) -> Tlv:
    """The document recommends type 1 (single-pose easy mode)."""
    if tune_type not in AUTOTUNE_TYPES:
        raise RangeError(f"auto-tune type {tune_type} is not 0 (default) or 1 (single pose)")
    return Tlv(AUTOTUNE, bytes(((tune_type << 1) | int(start),)))


def describe_user_param(tlv: Tlv) -> dict[str, int | str]:
    """A known user parameter as a readable name and value; unknown ones as hex."""
    value = tlv.value[0] if len(tlv.value) == 1 else None
    if tlv.id == PARAM_TABLE and value is not None:
        return {"param_table": value}
    if tlv.id == FOLLOW_SPECIAL and value is not None:
        mode = (value >> 3) & 0x07
        return {"roll360_mode": ROLL360_MODES.get(mode, f"0x{mode:X}")}
    if tlv.id == MOTOR_SPECIAL and value is not None:
        return {"motors_off": value & 0x01}
    return {f"0x{tlv.id:02X}": tlv.value.hex()}


def check_user_param(tlv: Tlv) -> None:
    """Refuse a user parameter the document does not define, or a value outside its range."""
    if tlv.id not in USER_PARAM_IDS:
        raise RangeError(f"user parameter 0x{tlv.id:02X} is not defined by the document "
                         f"(known: {', '.join(f'0x{i:02X}' for i in USER_PARAM_IDS)})")
    if len(tlv.value) != 1:
        raise RangeError(f"user parameter 0x{tlv.id:02X} takes 1 byte, not {len(tlv.value)}")
    value = tlv.value[0]
    if tlv.id == PARAM_TABLE and value > 2:
        raise RangeError(f"param_table={value} is outside 0..2")
    if tlv.id == FOLLOW_SPECIAL and (value & ~0x38 or (value >> 3) > 3):
        raise RangeError(f"roll360 mode byte 0x{value:02X}: bits 3..5 take 0..3, other bits are reserved")
    if tlv.id == MOTOR_SPECIAL and value & ~0x01:
        raise RangeError(f"motor special byte 0x{value:02X}: only bit 0 (motors off) is defined")


class _TlvPayload:
    """For messages whose whole payload is a TLV buffer held in a ``tlvs`` field."""

    NAME: ClassVar[str]
    tlvs: tuple[Tlv, ...]

    def encode_payload(self) -> bytes:
        self.validate()
        return encode_tlvs(self.tlvs)

    @classmethod
    def decode_payload(cls, payload: bytes) -> Self:
        return cls(decode_tlvs(payload, cls.NAME))


@dataclass
class _TlvReply(Reply):
    """A return code followed by a TLV buffer."""

    return_code: int = 0
    tlvs: tuple[Tlv, ...] = field(default_factory=tuple)

    def encode_payload(self) -> bytes:
        self.validate()
        return bytes((self.return_code,)) + encode_tlvs(self.tlvs)

    @classmethod
    def decode_payload(cls, payload: bytes) -> Self:
        if not payload:
            raise PayloadError(f"{cls.NAME}: empty payload")
        return cls(payload[0], decode_tlvs(payload[1:], cls.NAME))

    def validate(self) -> None:
        if not 0 <= self.return_code <= 0xFF:
            raise RangeError(f"{self.NAME}.return_code={self.return_code} is outside 0..255")
        encode_tlvs(self.tlvs)


@register
@dataclass
class UserParamsReply(_TlvReply):
    CMD_SET: ClassVar[int] = GIMBAL_CMD_SET
    CMD_ID: ClassVar[int] = 0x0B
    NAME: ClassVar[str] = "get_user_params_reply"


@register
@dataclass
class GetUserParams(Command):
    """Read one or more user parameters by TLV id."""

    CMD_SET: ClassVar[int] = GIMBAL_CMD_SET
    CMD_ID: ClassVar[int] = 0x0B
    NAME: ClassVar[str] = "get_user_params"
    REPLY: ClassVar = UserParamsReply
    read_ids: tuple[int, ...] = (PARAM_TABLE, FOLLOW_SPECIAL, MOTOR_SPECIAL)

    def encode_payload(self) -> bytes:
        self.validate()
        return bytes(self.read_ids)

    @classmethod
    def decode_payload(cls, payload: bytes) -> Self:
        if not payload:
            raise PayloadError(f"{cls.NAME}: no parameter ids")
        return cls(tuple(payload))

    def validate(self) -> None:
        if not self.read_ids:
            raise RangeError(f"{self.NAME}: give at least one parameter id")
        for pid in self.read_ids:
            if pid not in USER_PARAM_IDS:
                raise RangeError(f"user parameter 0x{pid:02X} is not defined by the document")


@register
@dataclass
class SetUserParamsReply(_TlvReply):
    CMD_SET: ClassVar[int] = GIMBAL_CMD_SET
    CMD_ID: ClassVar[int] = 0x0C
    NAME: ClassVar[str] = "set_user_params_reply"


@register
@dataclass
class SetUserParams(_TlvPayload, Command):
    """Write one or more user parameters (TLVs), e.g. ``motors_off(True)``."""

    CMD_SET: ClassVar[int] = GIMBAL_CMD_SET
    CMD_ID: ClassVar[int] = 0x0C
    NAME: ClassVar[str] = "set_user_params"
    REPLY: ClassVar = SetUserParamsReply
    tlvs: tuple[Tlv, ...] = field(default_factory=tuple)

    def validate(self) -> None:
        if not self.tlvs:
            raise RangeError(f"{self.NAME}: give at least one parameter")
        for tlv in self.tlvs:
            check_user_param(tlv)


@register
@dataclass
class AutoCalibrationReply(Reply):
    """The document shows no reply layout for 0x0F; firmware that answers sends a return code."""

    CMD_SET: ClassVar[int] = GIMBAL_CMD_SET
    CMD_ID: ClassVar[int] = 0x0F
    NAME: ClassVar[str] = "auto_calibration_reply"
    FORMAT: ClassVar[str] = "B"
    return_code: int = 0


@register
@dataclass
class AutoCalibration(_TlvPayload, Command):
    """Start or stop control-parameter auto-tuning (TLV 0x00), e.g. ``autotune(True)``."""

    CMD_SET: ClassVar[int] = GIMBAL_CMD_SET
    CMD_ID: ClassVar[int] = 0x0F
    NAME: ClassVar[str] = "auto_calibration"
    REPLY: ClassVar = AutoCalibrationReply
    tlvs: tuple[Tlv, ...] = field(default_factory=lambda: (autotune(True),))

    def validate(self) -> None:
        if not self.tlvs:
            raise RangeError(f"{self.NAME}: give at least one TLV")
        for tlv in self.tlvs:
            if tlv.id != AUTOTUNE or len(tlv.value) != 1:
                raise RangeError(f"calibration TLV 0x{tlv.id:02X} ({len(tlv.value)} bytes) is not "
                                 "defined by the document (only 0x00, 1 byte)")
            if (tlv.value[0] >> 1) not in AUTOTUNE_TYPES:
                raise RangeError(f"auto-tune type {tlv.value[0] >> 1} is not 0 (default) or 1 (single pose)")

    @property
    def start(self) -> bool | None:
        tlv = next((t for t in self.tlvs if t.id == AUTOTUNE), None)
        return None if tlv is None else bool(tlv.value[0] & 1)


@register
@dataclass
class CalibrationStatusPush(_TlvPayload, DevicePush):
    """Auto-calibration progress: state (0 idle, 1 running, 2 done, 3 error) and 0..100 %."""

    CMD_SET: ClassVar[int] = GIMBAL_CMD_SET
    CMD_ID: ClassVar[int] = 0x10
    NAME: ClassVar[str] = "calibration_status_push"
    tlvs: tuple[Tlv, ...] = field(default_factory=tuple)

    @classmethod
    def of(cls, state: int, progress: int, error: bytes = bytes(4)) -> CalibrationStatusPush:
        return cls((Tlv(AUTOTUNE, bytes((state, progress)) + error),))

    def validate(self) -> None:
        status = self._status_value()
        if status is None or len(status) != CALIBRATION_STATUS_LENGTH:
            raise RangeError(f"{self.NAME}: needs TLV 0x00 of {CALIBRATION_STATUS_LENGTH} bytes")
        encode_tlvs(self.tlvs)
        if status[0] not in CALIBRATION_STATES or status[1] > 100:
            raise RangeError(f"{self.NAME}: state {status[0]} / progress {status[1]} out of range")

    def _status_value(self) -> bytes | None:
        tlv = next((t for t in self.tlvs if t.id == AUTOTUNE), None)
        return tlv.value if tlv is not None and len(tlv.value) >= 2 else None

    @property
    def state(self) -> int | None:
        value = self._status_value()
        return None if value is None else value[0]

    @property
    def progress(self) -> int | None:
        value = self._status_value()
        return None if value is None else value[1]
