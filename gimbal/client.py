"""The typed commands of the DJI R SDK over the session core (``gimbal.session``): one method per
command of the document, in degrees, °/s and seconds.

Angles are degrees and speeds °/s in this API, any real numbers (numpy's too; not bools); they
are converted to the wire's 0.1 units by rounding to the nearest unit and range-checked by the
messages (``RangeError``, as is anything not a finite number) before anything is sent. Choices
such as the follow mode or the orientation are taken by name (the tables below) or by code.
"""
from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from typing import TypeVar

from gimbal.errors import GimbalError, RangeError
from gimbal.messages import Message, Reply
from gimbal.messages.camera import CameraAction, CameraActionCode, CameraStatusQuery
from gimbal.messages.external import (
    FOCUS_CALIBRATION_COMMANDS,
    DialPush,
    FocusCalibration,
    FocusPositionControl,
    FocusPositionQuery,
    FocusPositionReply,
    JoystickPush,
)
from gimbal.messages.motion import (
    ANGLES_ATTITUDE,
    ANGLES_JOINT,
    AXES,
    POSITION_ABSOLUTE,
    POSITION_INVALID,
    SPEED_HOLD,
    SPEED_RELEASE,
    AnglesReply,
    GetAngles,
    PositionControl,
    SpeedControl,
    to_raw,
)
from gimbal.messages.settings import (
    FOLLOW_FPV,
    FOLLOW_LOCK,
    FOLLOW_YAW,
    SELFIE,
    ActiveTrack,
    AngleLimitsReply,
    GetAngleLimits,
    GetMotorStiffness,
    MotorStiffnessReply,
    RecenterSelfie,
    SetAngleLimits,
    SetFollowMode,
    SetMotorStiffness,
    SetWorkMode,
)
from gimbal.messages.telemetry import (
    DEVICE_ID_R_SDK,
    PUSH_DISABLE,
    PUSH_ENABLE,
    PushControl,
    VersionPush,
    VersionQuery,
    VersionReply,
)
from gimbal.messages.tlv_params import (
    AutoCalibration,
    GetUserParams,
    SetUserParams,
    Tlv,
    autotune,
)
from gimbal.session import GimbalSession, stop_messages
from gimbal.values import integer, is_flag

__all__ = ["ANGLE_KINDS", "FOCUS_CALIBRATIONS", "FOLLOW_MODES", "ORIENTATIONS", "SPEED_HOLD",
           "SPEED_RELEASE", "Angles", "GimbalClient", "lookup", "position_message", "speed_message",
           "stop_messages"]

ANGLE_KINDS = {"attitude": ANGLES_ATTITUDE, "joint": ANGLES_JOINT}
FOLLOW_MODES = {"lock": FOLLOW_LOCK, "yaw": FOLLOW_YAW, "fpv": FOLLOW_FPV}
ORIENTATIONS = {"keep": 0x00, "landscape": 0x01, "landscape-flipped": 0x02, "portrait": 0x03,
                "portrait-flipped": 0x04, "toggle": 0x05, "default": 0xFF}
FOCUS_CALIBRATIONS = {name.replace("_", "-"): code for code, name in FOCUS_CALIBRATION_COMMANDS.items()}

R = TypeVar("R", bound=Reply)


@dataclass(frozen=True)
class Angles:
    """Gimbal angles in degrees; ``kind`` is "attitude" or "joint"."""

    kind: str
    yaw: float
    roll: float
    pitch: float


def position_message(yaw: float = 0.0, roll: float = 0.0, pitch: float = 0.0, *,
                     absolute: bool = True, time_s: float = 2.0,
                     axes: Iterable[str] = AXES) -> PositionControl:
    """Position control in degrees; axes not listed are flagged invalid (left where they are)."""
    moving = set(axes)
    unknown = moving - set(AXES)
    if unknown:
        raise RangeError(f"unknown axes {sorted(unknown)}; use yaw, roll, pitch")
    ctrl = POSITION_ABSOLUTE if absolute else 0
    raw = {}
    for axis, value in zip(AXES, (yaw, roll, pitch)):
        raw[axis] = to_raw(value, f"{axis} angle") if axis in moving else 0
        if axis not in moving:
            ctrl |= POSITION_INVALID[axis]
    return PositionControl(raw["yaw"], raw["roll"], raw["pitch"], ctrl, to_raw(time_s, "time"))


def flag(value: bool, name: str) -> bool:
    """``value`` as a bool when it is True or False (numpy's too); ``TypeError`` for anything else,
    such as the string "no", which Python would take as true."""
    if not is_flag(value):
        raise TypeError(f"{name} must be True or False, not {value!r}")
    return bool(value)


def speed_message(yaw: float, pitch: float, roll: float = 0.0, *,
                  take_control: bool = True) -> SpeedControl:
    """Speed control in °/s (±``MAX_SPEED_DPS``); bit 7 of ctrl_byte takes (or releases) control."""
    ctrl = SPEED_HOLD if flag(take_control, "take_control") else SPEED_RELEASE
    return SpeedControl(to_raw(yaw, "yaw speed"), to_raw(roll, "roll speed"),
                        to_raw(pitch, "pitch speed"), ctrl)


def lookup(table: dict[str, int], value: str | int, what: str) -> int:
    """A named choice (or its raw number) from ``table``; RangeError otherwise."""
    if integer(0)(value):  # numpy's too
        if value in table.values():
            return int(value)
    elif isinstance(value, str) and value in table:
        return table[value]
    raise RangeError(f"{what} {value!r} is not one of {', '.join(table)}")


class GimbalClient(GimbalSession):
    """A DJI RS gimbal on a python-can bus: the session (``gimbal.session.GimbalSession``: bus,
    Notifier, requests, pushes, safety stop) and one typed method per command of the document."""

    def _ask(self, message: Message, reply_type: type[R]) -> R:
        reply = self.request(message)
        if not isinstance(reply, reply_type):
            raise GimbalError(f"{message.NAME}: unexpected reply {type(reply).__name__}")
        return reply

    def _once(self, message: Message) -> None:
        """A command whose repetition would change the outcome: sent once, never retried."""
        self.request(message, retries=0)

    # -- motion ----------------------------------------------------------------------------

    def position(self, yaw: float = 0.0, roll: float = 0.0, pitch: float = 0.0, *,
                 absolute: bool = True, time_s: float = 2.0, axes: Iterable[str] = AXES) -> None:
        """Move to (absolute) or by (relative) the angles in degrees within ``time_s`` seconds.
        Relative moves are never retried."""
        message = position_message(yaw, roll, pitch, absolute=absolute, time_s=time_s, axes=axes)
        self.request(message, retries=None if absolute else 0)

    def speed(self, yaw: float, pitch: float, roll: float = 0.0, *, take_control: bool = True) -> None:
        """One speed command in °/s; the gimbal keeps it 0.5 s (use ``speed_streamer`` to hold it)."""
        self.request(speed_message(yaw, pitch, roll, take_control=take_control))

    def get_angles(self, kind: str = "attitude") -> Angles:
        """Attitude or joint angles in degrees."""
        code = lookup(ANGLE_KINDS, kind, "angle kind")
        reply = self._ask(GetAngles(code), AnglesReply)
        degrees = reply.degrees
        if reply.data_type != code or degrees is None:
            raise GimbalError(f"the gimbal has no {kind} angles ready (data_type {reply.data_type})")
        name = next(k for k, v in ANGLE_KINDS.items() if v == code)
        return Angles(name, *degrees)

    # -- settings --------------------------------------------------------------------------

    def set_angle_limits(self, pitch_max: int, pitch_min: int, yaw_max: int, yaw_min: int,
                         roll_max: int, roll_min: int) -> None:
        """User angle limits in whole degrees (min values are magnitudes below zero)."""
        self.request(SetAngleLimits(1, pitch_max, pitch_min, yaw_max, yaw_min, roll_max, roll_min))

    def get_angle_limits(self) -> AngleLimitsReply:
        """The user angle limits, whole degrees."""
        return self._ask(GetAngleLimits(), AngleLimitsReply)

    def set_stiffness(self, pitch: int, roll: int, yaw: int) -> None:
        """Motor stiffness 0..100 per axis."""
        self.request(SetMotorStiffness(1, pitch, roll, yaw))

    def get_stiffness(self) -> MotorStiffnessReply:
        """Motor stiffness 0..100 per axis."""
        return self._ask(GetMotorStiffness(), MotorStiffnessReply)

    def set_push(self, enabled: bool) -> None:
        """Enable or disable the parameter push (ParameterPush)."""
        self.request(PushControl(PUSH_ENABLE if flag(enabled, "enabled") else PUSH_DISABLE))

    def version(self, device_id: int = DEVICE_ID_R_SDK) -> VersionReply:
        """A module's version (``reply.version_text`` reads AA.BB.CC.DD)."""
        return self._ask(VersionQuery(device_id), VersionReply)

    def push_version(self, device_id: int, version: int) -> None:
        """Announce an external device's version to the gimbal (unanswered; repeat at 1 Hz)."""
        self.send(VersionPush(device_id, version))

    def joystick(self, yaw: int, pitch: int, roll: int = 0) -> None:
        """External joystick push, raw -15000..15000 per axis (unanswered)."""
        self.send(JoystickPush(pitch_speed=pitch, roll_speed=roll, yaw_speed=yaw))

    def dial(self, speed: int) -> None:
        """External dial push, raw -2048..2048 (unanswered)."""
        self.send(DialPush(dial_speed=speed))

    def get_user_params(self, ids: Iterable[int] | None = None) -> tuple[Tlv, ...]:
        """User parameters as TLVs (describe them with ``tlv_params.describe_user_param``)."""
        message = GetUserParams() if ids is None else GetUserParams(tuple(ids))
        return self.request(message).tlvs  # type: ignore[union-attr]

    def set_user_params(self, tlvs: Iterable[Tlv]) -> tuple[Tlv, ...]:
        """Write user parameters, e.g. ``[motors_off(True)]``; returns the TLVs echoed back."""
        return self.request(SetUserParams(tuple(tlvs))).tlvs  # type: ignore[union-attr]

    def set_work_mode(self, orientation: str | int) -> None:
        """Landscape/portrait orientation (names in ``ORIENTATIONS``)."""
        code = lookup(ORIENTATIONS, orientation, "orientation")
        message = SetWorkMode(orientation=code)
        self.request(message, retries=0 if code == ORIENTATIONS["toggle"] else None)

    def recenter(self) -> None:
        """Recenter once."""
        self.request(RecenterSelfie())

    def selfie(self) -> None:
        """Turn around for a selfie (a toggle: never retried)."""
        self._once(RecenterSelfie(action=SELFIE))

    def set_follow_mode(self, mode: str | int) -> None:
        """Follow mode: "lock", "yaw" or "fpv"."""
        self.request(SetFollowMode(lookup(FOLLOW_MODES, mode, "follow mode")))

    def auto_calibration(self, start: bool = True, type: int = 1) -> None:  # noqa: A002
        """Start or stop auto-tuning (type 1 = single pose, the document's advice). The document
        shows no reply, so it is sent reply-optional and silence is accepted."""
        self.request(AutoCalibration((autotune(flag(start, "start"), type),)), retries=0, optional=True)

    def activetrack_toggle(self) -> None:
        """Toggle ActiveTrack; reply-optional like ``auto_calibration``, never retried."""
        self.request(ActiveTrack(), retries=0, optional=True)

    # -- focus motor and camera ------------------------------------------------------------

    def focus_position(self, position: int) -> None:
        """Focus motor absolute position 0..4095 (a push: unanswered, up to 100 Hz)."""
        self.send(FocusPositionControl(position=position))

    def focus_calibration(self, command: str | int) -> bool:
        """Focus calibration command ("auto", "manual", "set-min", "set-max", "stop"); True if
        the motor reports success."""
        code = lookup(FOCUS_CALIBRATIONS, command, "focus calibration command")
        reply = self.request(FocusCalibration(calibration_cmd=code), retries=0)
        return getattr(reply, "result", 0) in (0, None)

    def focus_read(self) -> FocusPositionReply:
        """Focus motor calibration state and position."""
        return self._ask(FocusPositionQuery(), FocusPositionReply)

    def camera_action(self, code: int | CameraActionCode) -> None:
        """A camera action (photo, record start/stop, centre focus); never retried."""
        self._once(CameraAction(int(code)))

    def photo(self) -> None:
        self.camera_action(CameraActionCode.TAKE_PHOTO)

    def start_recording(self) -> None:
        self.camera_action(CameraActionCode.START_RECORDING)

    def stop_recording(self) -> None:
        self.camera_action(CameraActionCode.STOP_RECORDING)

    def camera_status(self) -> bool:
        """True while the camera records."""
        reply = self.request(CameraStatusQuery())
        recording = getattr(reply, "recording", None)
        if recording is None:
            raise GimbalError("camera status reply carries no status")
        return recording
