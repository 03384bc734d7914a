"""What the simulated gimbal does with each message: the document's semantics over the axis
model, independent of buses and threads (every method takes the time explicitly)."""
from __future__ import annotations

from collections import Counter
from collections.abc import Callable
from typing import Any

from gimbal.errors import ReturnCode
from gimbal.messages import Message, Reply, Tlv
from gimbal.messages import camera, external, motion, settings, telemetry, tlv_params
from gimbal.messages.limits import ANGLE_RANGES
from gimbal.messages.motion import AXES
from gimbal.messages.tlv_params import CALIBRATION_DONE, CALIBRATION_IDLE, CALIBRATION_RUNNING
from gimbal.sim.config import SimConfig
from gimbal.sim.dynamics import Axis, AxisMode, AxisRange, wrap180
from gimbal.sim.focus import FocusMotor
from gimbal.sim.state import SimState

MECHANICAL = {axis: (motion.from_raw(low), motion.from_raw(high))
              for axis, (low, high) in ANGLE_RANGES.items()}  # degrees
ORIENTATIONS = {0x01: 0, 0x02: 180, 0x03: 90, 0x04: -90, 0xFF: 0}
OK = int(ReturnCode.OK)
FAILED = int(ReturnCode.EXECUTION_FAILED)
JOYSTICK_FULL_SCALE = external.JOYSTICK_RANGE[1]
DIAL_FULL_SCALE = external.DIAL_RANGE[1]


class GimbalModel:
    """The device's state and behaviour. ``handle`` answers commands, ``apply_push`` takes host
    pushes, ``advance`` returns the device pushes due and ``next_due`` says when the next one is.
    Each of them (and ``snapshot``) first integrates the axes up to its ``now``, so the state is
    exact whenever it is looked at, however rarely ``advance`` is called."""

    def __init__(self, config: SimConfig, now: float) -> None:
        self.config = config
        self.axes = {name: Axis(angle, config.max_speed_dps, config.accel_dps2)
                     for name, angle in zip(AXES, config.initial_joint_deg)}
        self.limits = dict(pitch_max=145, pitch_min=55, yaw_max=179, yaw_min=179, roll_max=30, roll_min=30)
        self.stiffness = dict(pitch=50, roll=50, yaw=50)
        self.motors_off = False
        self.speed_control = False
        self.follow_mode = settings.FOLLOW_YAW
        self.orientation = 0
        self.selfie = False
        self.activetrack = False
        self.param_table = 0
        self.roll360_mode = 0
        self.push_enabled = False
        self.calibration = (CALIBRATION_IDLE, 0)
        self.focus = FocusMotor(config.focus_speed, config.focus_calibration_s)
        self.recording = False
        self.photos = 0
        self.external_versions: dict[int, int] = {}
        self.commands: Counter[str] = Counter()
        self._calibration_started = 0.0
        self._next_calibration_push = 0.0
        self._next_push = now
        self._integrated_to = now
        self._due_pushes: list[Message] = []  # raised by integration (calibration done), sent by advance
        self._handlers: dict[type[Message], Callable[[Any, float], Reply]] = {
            motion.PositionControl: self._position, motion.SpeedControl: self._speed,
            motion.GetAngles: self._get_angles, settings.SetAngleLimits: self._set_limits,
            settings.GetAngleLimits: self._get_limits, settings.SetMotorStiffness: self._set_stiffness,
            settings.GetMotorStiffness: self._get_stiffness, telemetry.PushControl: self._push_control,
            telemetry.VersionQuery: self._version, tlv_params.GetUserParams: self._get_params,
            tlv_params.SetUserParams: self._set_params, settings.SetWorkMode: self._work_mode,
            settings.RecenterSelfie: self._recenter_selfie, settings.SetFollowMode: self._follow_mode,
            tlv_params.AutoCalibration: self._auto_calibration, settings.ActiveTrack: self._activetrack,
            external.FocusCalibration: self._focus_calibration,
            external.FocusPositionQuery: self._focus_query, camera.CameraAction: self._camera_action,
            camera.CameraStatusQuery: self._camera_status,
        }
        self._pushes: dict[type[Message], Callable[[Any, float], None]] = {
            external.JoystickPush: self._joystick, external.DialPush: self._dial,
            telemetry.VersionPush: self._version_push, external.FocusPositionControl: self._focus_position,
        }
        for name, axis in self.axes.items():
            axis.angle = _clamp(axis.angle, self.axis_range(name))

    # --- dispatch -------------------------------------------------------------------------

    def handle(self, message: Message, now: float) -> Reply:
        """Execute a host command and return its reply."""
        self._integrate(now)
        self.commands[message.NAME] += 1
        return self._handlers[type(message)](message, now)

    def apply_push(self, message: Message, now: float) -> None:
        """Take a host push (never answered)."""
        self._integrate(now)
        self.commands[message.NAME] += 1
        self._pushes[type(message)](message, now)

    def refuse(self, message: Message, code: int) -> Reply:
        """Count ``message`` but do not execute it: the reply carries ``code`` alone, plus the
        echoed sub-command fields where the layout identifies itself by them (0x12; the focus
        position reply's defaults are those)."""
        self.commands[message.NAME] += 1
        reply_cls = message.REPLY
        assert reply_cls is not None, f"{message.NAME} has no reply"
        if reply_cls is external.FocusCalibrationReply:
            return external.FocusCalibrationReply(code, external.FOCUS_CALIBRATION, external.FOCUS_MOTOR, 1)
        return reply_cls(return_code=code)

    def blocked(self) -> str | None:
        """Why motion commands fail now, if they do."""
        if self.motors_off:
            return "motors off"
        if self.calibration[0] == CALIBRATION_RUNNING:
            return "auto-calibration running"
        return None

    # --- axes -------------------------------------------------------------------------------

    def axis_range(self, name: str) -> AxisRange:
        """Mechanical range intersected with the user limits (yaw may be continuous)."""
        if name == "yaw" and self.config.yaw_continuous:
            return AxisRange(-180.0, 180.0, wraps=True)
        low, high = MECHANICAL[name]
        return AxisRange(max(low, -self.limits[f"{name}_min"]), min(high, self.limits[f"{name}_max"]))

    def joint(self) -> tuple[float, float, float]:
        return tuple(self.axes[name].angle for name in AXES)  # type: ignore[return-value]

    def attitude(self) -> tuple[float, float, float]:
        yaw, roll, pitch = self.joint()
        return wrap180(yaw + self.config.base_yaw_deg), roll, pitch

    def _move_all(self, targets: dict[str, float], now: float, seconds: float, speed: float) -> None:
        """Uniform moves ending together, no faster than ``speed``."""
        span = max((abs(t - self.axes[n].angle) for n, t in targets.items()), default=0.0)
        duration = max(seconds, span / speed)
        for name, target in targets.items():
            self.axes[name].move_to(target, duration, now)

    def advance(self, now: float) -> list[Message]:
        """Integrate up to ``now``; return the device pushes due (parameter, calibration)."""
        self._integrate(now)
        pushes, self._due_pushes = self._due_pushes, []
        if self.calibration[0] == CALIBRATION_RUNNING and now >= self._next_calibration_push:
            pushes.append(tlv_params.CalibrationStatusPush.of(*self.calibration))
            self._next_calibration_push += 1.0 / self.config.calibration_push_hz
        if self.push_enabled and now >= self._next_push:
            pushes.append(self.parameter_push())
            period = 1.0 / self.config.push_rate_hz
            self._next_push = max(self._next_push + period, now - period / 2)
        return pushes

    def next_due(self) -> float | None:
        """When ``advance`` will next have a push to return (None: none is scheduled)."""
        times = [self._next_push] if self.push_enabled else []
        if self._due_pushes:
            times.append(self._integrated_to)
        if self.calibration[0] == CALIBRATION_RUNNING:
            times += [self._next_calibration_push, self._calibration_started + self.config.calibration_s]
        return min(times, default=None)

    def _integrate(self, now: float) -> None:
        """Bring the axes, the focus motor and the auto-calibration up to ``now``."""
        if now < self._integrated_to:
            return
        self._integrated_to = now
        for name, axis in self.axes.items():
            axis.advance(now, self.axis_range(name))
        self.focus.advance(now)
        if self.calibration[0] == CALIBRATION_RUNNING:
            elapsed = now - self._calibration_started
            if elapsed >= self.config.calibration_s:
                self.calibration = (CALIBRATION_DONE, 100)
                self._due_pushes.append(tlv_params.CalibrationStatusPush.of(CALIBRATION_DONE, 100))
            else:
                self.calibration = (CALIBRATION_RUNNING, min(99, int(100 * elapsed / self.config.calibration_s)))

    def parameter_push(self) -> telemetry.ParameterPush:
        att, joint = self.attitude(), self.joint()
        return telemetry.ParameterPush(
            telemetry.FLAG_ANGLES_VALID | telemetry.FLAG_LIMITS_VALID | telemetry.FLAG_STIFFNESS_VALID,
            *(motion.to_raw(a, "attitude") for a in att), *(motion.to_raw(a, "joint") for a in joint),
            **self.limits,
            pitch_stiffness=self.stiffness["pitch"], yaw_stiffness=self.stiffness["yaw"],
            roll_stiffness=self.stiffness["roll"])

    # --- motion -----------------------------------------------------------------------------

    def _position(self, msg: motion.PositionControl, now: float) -> Reply:
        if self.blocked():
            return msg.REPLY(FAILED)
        absolute = bool(msg.ctrl_byte & motion.POSITION_ABSOLUTE)
        values = {"yaw": msg.yaw_angle, "roll": msg.roll_angle, "pitch": msg.pitch_angle}
        targets = {}
        for name, raw in values.items():
            if msg.ctrl_byte & motion.POSITION_INVALID[name]:
                continue
            target = motion.from_raw(raw) if absolute else self.axes[name].angle + motion.from_raw(raw)
            if not self.axis_range(name).contains(target):
                return msg.REPLY(FAILED)
            targets[name] = target
        self._move_all(targets, now, motion.from_raw(msg.time_for_action), self.config.max_speed_dps)
        self.selfie = False
        return msg.REPLY(OK)

    def _speed(self, msg: motion.SpeedControl, now: float) -> Reply:
        if not msg.ctrl_byte & motion.SPEED_TAKE_CONTROL:
            self.speed_control = False
            for axis in self.axes.values():
                if axis.mode is AxisMode.SPEED:
                    axis.stop()
            return msg.REPLY(OK)
        if self.blocked():
            return msg.REPLY(FAILED)
        self.speed_control = True
        speeds = (msg.yaw_speed, msg.roll_speed, msg.pitch_speed)
        for name, raw, sign in zip(AXES, speeds, self.config.speed_signs):
            self.axes[name].set_speed(sign * motion.from_raw(raw), now, self.config.speed_timeout_s)
        return msg.REPLY(OK)

    def _joystick(self, msg: external.JoystickPush, now: float) -> None:
        if self.blocked():
            return
        scale = self.config.joystick_full_scale_dps / JOYSTICK_FULL_SCALE
        speeds = (msg.yaw_speed, msg.roll_speed, msg.pitch_speed)
        for name, raw, sign in zip(AXES, speeds, self.config.speed_signs):
            self.axes[name].set_speed(sign * raw * scale, now, self.config.speed_timeout_s)

    def _recenter_selfie(self, msg: settings.RecenterSelfie, now: float) -> Reply:
        if self.blocked():
            return msg.REPLY(FAILED)
        selfie = msg.action == settings.SELFIE and not self.selfie
        yaw = _clamp(180.0, self.axis_range("yaw")) if selfie else 0.0
        self._move_all({"yaw": yaw, "roll": 0.0, "pitch": 0.0}, now, 0.0, self.config.recenter_speed_dps)
        self.selfie = selfie
        return msg.REPLY(OK)

    def _get_angles(self, msg: motion.GetAngles, now: float) -> Reply:
        if msg.ctrl_byte == motion.ANGLES_NONE:
            return msg.REPLY(OK, motion.ANGLES_NONE, 0, 0, 0)
        angles = self.attitude() if msg.ctrl_byte == motion.ANGLES_ATTITUDE else self.joint()
        return msg.REPLY(OK, msg.ctrl_byte, *(motion.to_raw(a, "angle") for a in angles))

    # --- settings ---------------------------------------------------------------------------

    def _set_limits(self, msg: settings.SetAngleLimits, now: float) -> Reply:
        if msg.ctrl_byte == settings.DO_OPERATION:
            self.limits = {k: getattr(msg, k) for k in self.limits}
            outside = {n: _clamp(self.axes[n].angle, self.axis_range(n)) for n in AXES
                       if not self.axis_range(n).contains(self.axes[n].angle)}
            if outside and not self.motors_off:
                self._move_all(outside, now, 0.0, self.config.recenter_speed_dps)
        return msg.REPLY(OK)

    def _get_limits(self, msg: settings.GetAngleLimits, now: float) -> Reply:
        if msg.ctrl_byte == settings.NO_OPERATION:
            return msg.REPLY(OK)
        return msg.REPLY(OK, **self.limits)

    def _set_stiffness(self, msg: settings.SetMotorStiffness, now: float) -> Reply:
        if msg.ctrl_byte == settings.DO_OPERATION:
            self.stiffness = dict(pitch=msg.pitch_stiffness, roll=msg.roll_stiffness, yaw=msg.yaw_stiffness)
        return msg.REPLY(OK)

    def _get_stiffness(self, msg: settings.GetMotorStiffness, now: float) -> Reply:
        if msg.ctrl_byte == settings.NO_OPERATION:
            return msg.REPLY(OK)
        return msg.REPLY(OK, pitch_stiffness=self.stiffness["pitch"], yaw_stiffness=self.stiffness["yaw"],
                         roll_stiffness=self.stiffness["roll"])

    def _push_control(self, msg: telemetry.PushControl, now: float) -> Reply:
        if msg.ctrl_byte == telemetry.PUSH_ENABLE:
            if not self.push_enabled:
                self._next_push = now
            self.push_enabled = True
        elif msg.ctrl_byte == telemetry.PUSH_DISABLE:
            self.push_enabled = False
        return msg.REPLY(OK)

    def _version(self, msg: telemetry.VersionQuery, now: float) -> Reply:
        if msg.device_id != self.config.device_id:
            return msg.REPLY(FAILED, msg.device_id)
        return msg.REPLY(OK, msg.device_id, self.config.version)

    def _version_push(self, msg: telemetry.VersionPush, now: float) -> None:
        self.external_versions[msg.device_id] = msg.version

    def _param_tlv(self, pid: int) -> Tlv:
        if pid == tlv_params.PARAM_TABLE:
            return tlv_params.param_table(self.param_table)
        if pid == tlv_params.FOLLOW_SPECIAL:
            return tlv_params.roll360_mode(self.roll360_mode)
        return tlv_params.motors_off(self.motors_off)

    def _get_params(self, msg: tlv_params.GetUserParams, now: float) -> Reply:
        return msg.REPLY(OK, tuple(self._param_tlv(pid) for pid in msg.read_ids))

    def _set_params(self, msg: tlv_params.SetUserParams, now: float) -> Reply:
        for tlv in msg.tlvs:
            value = tlv.value[0]
            if tlv.id == tlv_params.PARAM_TABLE:
                self.param_table = value
            elif tlv.id == tlv_params.FOLLOW_SPECIAL:
                self.roll360_mode = (value >> 3) & 0x07
            else:
                self.motors_off = bool(value & 0x01)
                if self.motors_off:
                    self.speed_control = False
                    for axis in self.axes.values():
                        axis.halt()
        return msg.REPLY(OK, tuple(self._param_tlv(tlv.id) for tlv in msg.tlvs))

    def _work_mode(self, msg: settings.SetWorkMode, now: float) -> Reply:
        if msg.orientation and self.motors_off:
            return msg.REPLY(FAILED)
        if msg.orientation == 0x05:
            self.orientation = 90 if self.orientation in (0, 180) else 0
        elif msg.orientation in ORIENTATIONS:
            self.orientation = ORIENTATIONS[msg.orientation]
        return msg.REPLY(OK)

    def _follow_mode(self, msg: settings.SetFollowMode, now: float) -> Reply:
        self.follow_mode = msg.work_mode
        return msg.REPLY(OK)

    def _auto_calibration(self, msg: tlv_params.AutoCalibration, now: float) -> Reply:
        running = self.calibration[0] == CALIBRATION_RUNNING
        if not msg.start:
            if running:
                self.calibration = (CALIBRATION_IDLE, 0)
            return msg.REPLY(OK)
        if running or self.motors_off:
            return msg.REPLY(FAILED)
        for axis in self.axes.values():
            axis.halt()
        self.speed_control = False
        self.calibration = (CALIBRATION_RUNNING, 0)
        self._calibration_started = self._next_calibration_push = now
        return msg.REPLY(OK)

    def _activetrack(self, msg: settings.ActiveTrack, now: float) -> Reply:
        self.activetrack = not self.activetrack
        return msg.REPLY(OK)

    # --- focus motor and camera ---------------------------------------------------------------

    def _focus_position(self, msg: external.FocusPositionControl, now: float) -> None:
        self.focus.move_to(msg.position)

    def _dial(self, msg: external.DialPush, now: float) -> None:
        self.focus.dial(msg.dial_speed / DIAL_FULL_SCALE, now, self.config.speed_timeout_s)

    def _focus_calibration(self, msg: external.FocusCalibration, now: float) -> Reply:
        """A calibration step that cannot be done is reported in ``result`` (1), not the return code."""
        done = self.focus.calibrate(msg.calibration_cmd, now)
        return msg.REPLY(OK, msg.sub_id, msg.motor_type, 0 if done else 1)

    def _focus_query(self, msg: external.FocusPositionQuery, now: float) -> Reply:
        return msg.REPLY(OK, msg.sub_id, msg.motor_type, self.focus.state, round(self.focus.position))

    def _camera_action(self, msg: camera.CameraAction, now: float) -> Reply:
        if not self.config.camera_connected:
            return msg.REPLY(FAILED)
        if msg.action == camera.CameraActionCode.START_RECORDING:
            self.recording = True
        elif msg.action == camera.CameraActionCode.STOP_RECORDING:
            self.recording = False
        elif msg.action == camera.CameraActionCode.TAKE_PHOTO:
            self.photos += 1
        return msg.REPLY(OK)

    def _camera_status(self, msg: camera.CameraStatusQuery, now: float) -> Reply:
        if not self.config.camera_connected:
            return msg.REPLY(FAILED)
        return msg.REPLY(OK, camera.RECORDING if self.recording else camera.NOT_RECORDING)

    # --- snapshot -----------------------------------------------------------------------------

    def snapshot(self, now: float, sent: Counter[str], faults: Counter[str]) -> SimState:
        self._integrate(now)
        return SimState(
            time=now, attitude=self.attitude(), joint=self.joint(),
            speeds=tuple(self.axes[n].velocity for n in AXES),  # type: ignore[arg-type]
            axis_modes=tuple(self.axes[n].mode.value for n in AXES),  # type: ignore[arg-type]
            moving=any(a.velocity or a.mode is AxisMode.MOVE for a in self.axes.values()),
            motors_on=not self.motors_off, speed_control=self.speed_control, limits=dict(self.limits),
            stiffness=dict(self.stiffness), follow_mode=self.follow_mode, orientation_deg=self.orientation,
            selfie=self.selfie, activetrack=self.activetrack, param_table=self.param_table,
            roll360_mode=self.roll360_mode, push_enabled=self.push_enabled, calibration=self.calibration,
            focus={"position": self.focus.position, "target": self.focus.target, "state": self.focus.state},
            recording=self.recording, photos=self.photos, external_versions=dict(self.external_versions),
            commands=dict(self.commands), sent=dict(sent), faults=dict(faults))


def _clamp(angle: float, allowed: AxisRange) -> float:
    return angle if allowed.wraps else min(allowed.high, max(allowed.low, angle))

