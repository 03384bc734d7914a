"""Rate controllers: target estimate + gimbal attitude -> yaw/pitch speed setpoints.

All times (``now``, estimate timestamps, attitude times) must share one monotonic clock.
"""
from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass
from typing import Protocol

from pipelines.control.camera import CameraModel
from pipelines.control.direction import Direction, DirectionFilter, PredictionTrust, compose, wrap_deg
from pipelines.control.gimbal_link import SETPOINT_MAX_AGE_S
from pipelines.control.limits import PROTOCOL_MAX_SPEED_DPS, limit_rate
from pipelines.control.pid import Pid
from tracker.runtime.estimate import TargetEstimate, TrackState


@dataclass(frozen=True, slots=True)
class ControlConfig:
    """Limits, gains and timing of the closed loop (degrees, seconds)."""

    max_speed_dps: float = 120.0
    max_accel_dps2: float = 600.0
    kp: float = 12.0  # deg/s per deg of error (small errors; large ones see brake_accel_dps2)
    ki: float = 1.0
    kd: float = 0.0
    integral_limit_dps: float = 30.0
    deadband_deg: float = 0.05
    feedforward: float = 1.0  # share of the target's angular velocity fed forward
    actuation_delay_s: float = 0.06  # setpoint -> gimbal motion (keep-alive period, bus, motor lag)
    max_prediction_s: float = 0.35  # cap on how far ahead the target is extrapolated
    hold_s: float = 0.1  # after a loss, keep following the prediction this long ...
    ramp_s: float = 0.2  # ... then ramp linearly to zero speed over this long
    brake_accel_dps2: float = 300.0  # closing speed at most sqrt(2 * this * |error|): no overshoot
    measurement_std_deg: float = 0.15
    target_accel_std_dps2: float = 300.0
    trust_memory_s: float = 1.0  # memory of the prediction scoring (PredictionTrust)
    reversal_factor: float = 2.0  # scoring horizon += this * (time to reverse the target's speed)
    first_step_s: float = 1 / 30  # the first setpoint may step from rest by max_accel_dps2 * this
    setpoint_max_age_s: float = SETPOINT_MAX_AGE_S  # the keep-alive streams zero once a setpoint is this old

    def __post_init__(self) -> None:
        for name in self.__dataclass_fields__:
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int | float) or math.isnan(value):
                raise ValueError(f"ControlConfig.{name} must be a number, not {value!r}")
        if not 0.0 < self.max_speed_dps <= PROTOCOL_MAX_SPEED_DPS:
            raise ValueError(f"max_speed_dps must be in (0, {PROTOCOL_MAX_SPEED_DPS:g}]")
        if (self.max_accel_dps2 <= 0 or self.hold_s < 0 or self.ramp_s <= 0 or self.first_step_s <= 0
                or self.setpoint_max_age_s <= 0):
            raise ValueError("max_accel_dps2, ramp_s, first_step_s and setpoint_max_age_s must be positive, "
                             "hold_s non-negative")
        if self.max_speed_dps / self.ramp_s > self.max_accel_dps2 * (1 + 1e-9):
            raise ValueError("the stop ramp from max_speed_dps over ramp_s would exceed max_accel_dps2")

    @property
    def stop_within_s(self) -> float:
        """Worst-case time from losing the target to zero speed."""
        return self.hold_s + self.ramp_s


@dataclass(frozen=True, slots=True)
class RateCommand:
    """One speed setpoint (deg/s) and why it was chosen.

    ``stamp`` is the capture time of the frame behind it (for the streamer's latency figures);
    ``mode`` is ``track``, ``hold`` (target missing, following the prediction), ``ramp``
    (slowing to zero) or ``idle``; errors are world-frame degrees (target minus predicted pointing),
    NaN when no target stands behind the setpoint (``idle``, ``ramp``).
    """

    yaw_dps: float
    pitch_dps: float
    roll_dps: float = 0.0
    stamp: float | None = None
    mode: str = "idle"
    yaw_error_deg: float = math.nan
    pitch_error_deg: float = math.nan
    latency_s: float = 0.0


class Controller(Protocol):
    config: ControlConfig

    def update(self, estimate: TargetEstimate | None, attitude: tuple[float, float] | None,
               now: float) -> RateCommand: ...

    def reset(self) -> None: ...

    def retune(self, config: ControlConfig) -> None: ...


def _check_now(last_now: float | None, now: float) -> None:
    """``ValueError`` unless ``now`` is finite and not before the previous update's (one monotonic clock)."""
    if not math.isfinite(now) or last_now is not None and now < last_now:
        raise ValueError(f"now={now!r} must be a finite time, not before the previous update's {last_now!r}")


def _time_step(config: ControlConfig, last_now: float | None, now: float) -> tuple[float, bool]:
    """The time step the PID and the acceleration limit see, and whether the loop starts from rest.

    At the start, and after a gap in which the keep-alive has replaced the last setpoint by zero
    (longer than ``setpoint_max_age_s``), the gimbal was last told zero: the next setpoint steps
    from rest as if that zero were ``first_step_s`` old, instead of integrating the whole gap.
    """
    if last_now is None or now - last_now > config.setpoint_max_age_s:
        return config.first_step_s, True
    return now - last_now, False


def _tracking(estimate: TargetEstimate | None) -> bool:
    """A detection to steer by: tracked, with a finite centre (a NaN would poison the filter)."""
    return (estimate is not None and estimate.state is TrackState.TRACKING
            and all(math.isfinite(v) for v in estimate.center))


class RateController:
    """World-frame PID + feed-forward of the target's angular velocity, latency compensated.

    Each detection is turned into a world direction (image offset composed with the gimbal
    attitude at the frame's time) and filtered by a constant-velocity Kalman filter. The target
    is extrapolated to when the new setpoint will act (``now + actuation_delay_s``), at most
    ``max_prediction_s`` past its frame and held there beyond; the gimbal's pointing at that same
    time is predicted from the attitude at frame time plus all the setpoints already sent (a Smith
    predictor), so pipeline latency does not destabilise the loop. Without a measured attitude
    the pointing is dead-reckoned from the setpoints once one has been measured; before any, the
    loop works in the camera's frame (see ``_take_attitude``).
    The extrapolation and the feed-forward are scaled by a trust (:class:`PredictionTrust`):
    the share of the predicted motion that has been coming true over the time the loop needs
    to act and to reverse the target's speed at the acceleration limit. Smooth motion keeps it
    near 1; a subject whose speed jumps (throws, catches, bounces) drives it down, so the gimbal
    does not commit to speeds it cannot shed in time (the overshoot that loses a juggled ball).
    Large errors close at the speed from which the gimbal can still stop (``brake_accel_dps2``).
    Without detections it follows the prediction for ``hold_s``, then ramps to zero over ``ramp_s``.
    """

    def __init__(self, camera: CameraModel, config: ControlConfig | None = None) -> None:
        self.camera = camera
        self.config = config or ControlConfig()
        self.reset()

    def _pid(self) -> Pid:
        c = self.config
        return Pid(c.kp, c.ki, c.kd, output_limit=c.max_speed_dps,
                   integral_limit=c.integral_limit_dps, deadband=c.deadband_deg)

    def reset(self) -> None:
        c = self.config
        self._filter = DirectionFilter(c.measurement_std_deg, c.target_accel_std_dps2)
        self._trust = PredictionTrust(c.trust_memory_s)
        self._pid_yaw, self._pid_pitch = self._pid(), self._pid()
        self._direction: Direction | None = None
        self._attitude: tuple[float, float, float] | None = None  # yaw, pitch, time
        self._assumed = False  # _attitude is the camera's frame, (0, 0) at capture: none measured yet
        self._reckoned = False  # frames since the last measured attitude were placed by dead-reckoning
        self._sent: deque[tuple[float, float, float]] = deque(maxlen=256)  # time, yaw, pitch
        self._last_now: float | None = None
        self._last_good: float = -math.inf
        self._ramp_from: tuple[float, float] | None = None
        self._yaw_unwrapped = 0.0
        self._last = RateCommand(0.0, 0.0)

    def retune(self, config: ControlConfig) -> None:
        """New limits, gains and dead band from the next update on (an operator's live settings),
        keeping the target's filter and each PID's integral and output, so nothing jumps."""
        self.config = config
        for pid in (self._pid_yaw, self._pid_pitch):
            pid.kp, pid.ki, pid.kd = config.kp, config.ki, config.kd
            pid.output_limit, pid.integral_limit = config.max_speed_dps, config.integral_limit_dps
            pid.deadband = config.deadband_deg

    def _take_attitude(self, attitude: tuple[float, float] | None, frame_t: float, captured: bool) -> bool:
        """Set the pointing reference: the measured ``attitude`` at ``frame_t``; else, once one was
        measured, dead-reckoned (moved up to each frame's capture time, so the setpoints before it
        are no longer needed); before any, (0, 0) at each frame's capture: the loop then works in
        the camera's frame, as without attitude feedback (dead-reckoning from an unknown start
        grew without bound against a gimbal at its stop, and past 90 deg of pitch turned the
        commands round). True when a measured attitude replaces the assumed one: the world frame
        has changed."""
        if attitude is not None:
            reframed = self._assumed
            if self._reckoned:
                self._correct_reckoning(attitude, frame_t)
            self._attitude, self._assumed, self._reckoned = (attitude[0], attitude[1], frame_t), False, False
            return reframed
        if self._attitude is None or (self._assumed and captured):
            self._attitude, self._assumed = (0.0, 0.0, frame_t), True
            return False
        self._reckoned = True
        if captured and frame_t > self._attitude[2]:
            self._attitude = (*self._pointing(frame_t), frame_t)
        return False

    def _correct_reckoning(self, attitude: tuple[float, float], frame_t: float) -> None:
        """The attitude is back after frames placed by dead-reckoning: the target was measured
        against a pointing off by as much as the reckoning drifted, so move it by the same (the
        correction would otherwise look like a jump of the target)."""
        reckoned = self._pointing(frame_t)
        dyaw, dpitch = wrap_deg(attitude[0] - reckoned[0]), attitude[1] - reckoned[1]
        self._filter.shift(dyaw, dpitch)
        self._trust.shift(dyaw, dpitch)
        if self._direction is not None:
            self._direction = self._direction.shifted(dyaw, dpitch)

    def _forget_target(self) -> None:
        """Start the target's filter, trust and PID afresh (a new acquisition, a new world frame)."""
        self._filter.reset()
        self._trust.reset()
        self._direction = None
        self._pid_yaw.reset(self._last.yaw_dps)
        self._pid_pitch.reset(self._last.pitch_dps)

    def _restart_from_rest(self) -> None:
        """Forget the PID state and take the last setpoint as zero, as the gimbal was told."""
        self._pid_yaw.reset()
        self._pid_pitch.reset()
        self._last = RateCommand(0.0, 0.0)

    def _integrate_sent(self, t0: float, t1: float) -> tuple[float, float]:
        """Angle (yaw, pitch) swept by the setpoints sent between times t0 and t1 (each one holds
        until the next, or until the keep-alive replaces it by zero; they are sent in time order,
        so the walk back stops at the one before t0)."""
        dyaw = dpitch = 0.0
        if t1 <= t0:  # no span can be positive: the pointing at the attitude's own time, every frame
            return dyaw, dpitch
        end, max_age = t1, self.config.setpoint_max_age_s
        for t, yaw, pitch in reversed(self._sent):
            span = min(end, t1, t + max_age) - max(t, t0)
            if span > 0:
                dyaw += yaw * span
                dpitch += pitch * span
            if t <= t0:
                break
            end = t
        return dyaw, dpitch

    def _pointing(self, t: float) -> tuple[float, float]:
        """Gimbal (yaw, pitch) at time ``t``: the last known attitude plus the motion of the
        setpoints sent since, each acting ``actuation_delay_s`` after it was sent."""
        yaw, pitch, t_ref = self._attitude
        delay = self.config.actuation_delay_s
        dyaw, dpitch = self._integrate_sent(t_ref - delay, t - delay)
        return wrap_deg(yaw + dyaw), pitch + dpitch

    def update(self, estimate: TargetEstimate | None, attitude: tuple[float, float] | None,
               now: float) -> RateCommand:
        """One setpoint for the frame behind ``estimate`` (``None``: no frame or no detection).

        ``attitude`` is the gimbal (yaw, pitch) in degrees at the frame's capture time (at ``now``
        without an estimate); when ``None`` it is dead-reckoned from the setpoints sent, or, if none
        was ever given, taken as (0, 0) at each capture (the camera's frame).
        """
        c = self.config
        _check_now(self._last_now, now)
        dt, from_rest = _time_step(c, self._last_now, now)
        self._last_now = now
        if from_rest:
            self._restart_from_rest()
        frame_t = estimate.timestamp if estimate is not None else now
        if self._take_attitude(attitude, frame_t, captured=estimate is not None):
            self._forget_target()  # the world frame moved from the assumed attitude to the measured one

        measured = _tracking(estimate)
        if measured:
            if now - self._last_good > c.stop_within_s:  # a new acquisition starts afresh
                self._forget_target()
            world = compose(self._pointing(frame_t), self.camera.pixel_to_angles(*estimate.center))
            if attitude is not None:  # with a dead-reckoned pointing it would score our own model
                self._trust.observe(world, frame_t, self._scoring_horizon(now, frame_t))
            self._direction = self._filter.update(world, frame_t)
            self._trust.add(self._direction)
            self._last_good = now
            self._ramp_from = None
        elif estimate is not None and self._direction is not None:
            self._direction = self._filter.update(None, frame_t)

        if dt <= 0.0:  # no time has passed: nothing new to command
            return self._last
        since = now - self._last_good
        if self._direction is None or since >= c.stop_within_s - 1e-9:
            return self._emit(0.0, 0.0, "idle", dt, estimate, now)
        if since > c.hold_s:
            if self._ramp_from is None:
                self._ramp_from = (self._last.yaw_dps, self._last.pitch_dps)
            keep = max(0.0, 1.0 - (since - c.hold_s) / c.ramp_s)
            # validated: max_speed / ramp_s <= max_accel, so the linear ramp respects the limit
            return self._emit(self._ramp_from[0] * keep, self._ramp_from[1] * keep, "ramp", dt,
                              estimate, now, limit_accel=False)
        return self._follow(dt, now, estimate, "track" if measured else "hold")

    def _scoring_horizon(self, now: float, frame_t: float) -> float:
        """How far ahead the prediction must hold: from the frame to when the setpoint acts,
        plus the time the gimbal needs to reverse the target's speed at the acceleration limit
        (a gimbal that matched a speed that then reverses is wrong for that long, and about as
        long again while it recovers the angle lost: hence ``reversal_factor`` 2)."""
        c, d = self.config, self._direction
        speed = 0.0 if d is None else math.hypot(d.yaw_rate, d.pitch_rate)
        return now + c.actuation_delay_s - frame_t + c.reversal_factor * 2.0 * speed / c.max_accel_dps2

    def _follow(self, dt: float, now: float, estimate: TargetEstimate | None, mode: str) -> RateCommand:
        c, d = self.config, self._direction
        t_act = now + c.actuation_delay_s
        w = self._trust.weight  # use the prediction only as far as it has been coming true
        ahead = d.at(min(t_act, d.timestamp + c.max_prediction_s))  # held beyond the horizon
        target = wrap_deg(d.yaw + w * wrap_deg(ahead[0] - d.yaw)), d.pitch + w * (ahead[1] - d.pitch)
        gimbal = self._pointing(t_act)
        e_yaw, e_pitch = wrap_deg(target[0] - gimbal[0]), target[1] - gimbal[1]
        self._yaw_unwrapped += wrap_deg(gimbal[0] - self._yaw_unwrapped)
        ff_yaw, ff_pitch = w * c.feedforward * d.yaw_rate, w * c.feedforward * d.pitch_rate
        (seen_yaw, shaped_yaw), (seen_pitch, shaped_pitch) = self._shaped(e_yaw), self._shaped(e_pitch)
        yaw = ff_yaw + self._pid_yaw(seen_yaw, dt, measurement=self._yaw_unwrapped,
                                     bounds=self._reachable(self._last.yaw_dps, dt, ff_yaw),
                                     integrate=not shaped_yaw)
        pitch = ff_pitch + self._pid_pitch(seen_pitch, dt, measurement=gimbal[1],
                                           bounds=self._reachable(self._last.pitch_dps, dt, ff_pitch),
                                           integrate=not shaped_pitch)
        return self._emit(yaw, pitch, mode, dt, estimate, now, (e_yaw, e_pitch))

    def _reachable(self, last: float, dt: float, offset: float) -> tuple[float, float]:
        """The range the PID's share of a setpoint can take this step (the speed and acceleration
        limits ``_emit`` applies, less ``offset``, the feed-forward), so it does not integrate what
        the limits hold back."""
        c = self.config
        speed, step = min(c.max_speed_dps, PROTOCOL_MAX_SPEED_DPS), c.max_accel_dps2 * dt
        return max(-speed, last - step) - offset, min(speed, last + step) - offset

    def _shaped(self, error: float) -> tuple[float, bool]:
        """The error the PID sees, and whether it was shrunk (the PID then does not integrate):
        unchanged while kp * |error| <= sqrt(2 * brake * |error|), beyond that shrunk so the
        closing speed is the speed from which the gimbal can still stop on the target at
        ``brake_accel_dps2`` (large steps close fast without overshoot)."""
        c, e = self.config, abs(error)
        if not c.kp * c.kp * e > 2.0 * c.brake_accel_dps2:  # not <=: a NaN error passes unchanged
            return error, False
        return math.copysign(math.sqrt(2.0 * c.brake_accel_dps2 * e) / c.kp, error), True

    def _emit(self, yaw: float, pitch: float, mode: str, dt: float, estimate: TargetEstimate | None,
              now: float, errors: tuple[float, float] = (math.nan, math.nan), limit_accel: bool = True) -> RateCommand:
        c = self.config
        accel = c.max_accel_dps2 if limit_accel else math.inf
        yaw = limit_rate(self._last.yaw_dps, yaw, c.max_speed_dps, accel, dt)
        pitch = limit_rate(self._last.pitch_dps, pitch, c.max_speed_dps, accel, dt)
        self._sent.append((now, yaw, pitch))
        stamp = estimate.timestamp if estimate is not None else None
        self._last = RateCommand(yaw, pitch, 0.0, stamp, mode, errors[0], errors[1],
                                 0.0 if stamp is None else now - stamp)
        return self._last


class ProportionalController:
    """Baseline as public drivers do it: speed proportional to the pixel error, nothing else.

    ``gain_per_s`` is the loop gain near the image centre (deg/s per deg of error); the pixel
    gain is ``gain_per_s`` times the degrees per pixel at the centre. On loss it slows to zero
    as fast as the acceleration limit allows. The attitude is not used.
    """

    def __init__(self, camera: CameraModel, config: ControlConfig | None = None,
                 gain_per_s: float = 3.0) -> None:
        self.camera = camera
        self.config = config or ControlConfig()
        self.gain_per_px = gain_per_s * math.degrees(1.0 / camera.focal_px)
        self.reset()

    def _pid(self) -> Pid:
        c = self.config
        return Pid(self.gain_per_px, output_limit=min(c.max_speed_dps, PROTOCOL_MAX_SPEED_DPS),
                   slew_rate=c.max_accel_dps2)

    def reset(self) -> None:
        self._pid_yaw, self._pid_pitch = self._pid(), self._pid()
        self._last_now: float | None = None
        self._last = RateCommand(0.0, 0.0)

    def retune(self, config: ControlConfig) -> None:
        """New speed and acceleration limits from the next update on; the baseline's gain is its
        own (``gain_per_s``), so a config whose PID gains or dead band differ is refused."""
        fixed = [n for n in ("kp", "ki", "kd", "deadband_deg") if getattr(config, n) != getattr(self.config, n)]
        if fixed:
            raise ValueError(f"the p controller has a fixed gain and no dead band: {', '.join(fixed)} "
                             "apply to the pid controller only")
        self.config = config
        for pid in (self._pid_yaw, self._pid_pitch):
            pid.output_limit = min(config.max_speed_dps, PROTOCOL_MAX_SPEED_DPS)
            pid.slew_rate = config.max_accel_dps2

    def update(self, estimate: TargetEstimate | None, attitude: tuple[float, float] | None,
               now: float) -> RateCommand:
        _check_now(self._last_now, now)
        if self._last_now is None:  # as public drivers do: the first frame only starts the clock
            dt = 0.0
        else:
            dt, from_rest = _time_step(self.config, self._last_now, now)
            if from_rest:  # the keep-alive has zeroed the last setpoint: slew on from zero
                self._pid_yaw.reset()
                self._pid_pitch.reset()
        self._last_now = now
        if dt <= 0.0:
            return self._last
        if _tracking(estimate):
            cx, cy = estimate.center
            dx, dy = cx - self.camera.cx, cy - self.camera.cy
            mode = "track"
        else:
            dx = dy = 0.0
            mode = "idle"
        yaw = self._pid_yaw(dx, dt)
        pitch = self._pid_pitch(-dy, dt)
        stamp = estimate.timestamp if estimate is not None else None
        e_yaw, e_pitch = (self.camera.pixel_to_angles(self.camera.cx + dx, self.camera.cy + dy)
                          if mode == "track" else (math.nan, math.nan))
        self._last = RateCommand(yaw, pitch, 0.0, stamp, mode, e_yaw, e_pitch,
                                 0.0 if stamp is None else now - stamp)
        return self._last


CONTROLLERS = {"pid": RateController, "p": ProportionalController}


def controller_names() -> list[str]:
    return list(CONTROLLERS)


def make_controller(name: str = "pid", *, camera: CameraModel,
                    config: ControlConfig | None = None) -> Controller:
    """A controller by name: ``pid`` (:class:`RateController`) or ``p`` (the baseline)."""
    if name not in CONTROLLERS:
        raise ValueError(f"unknown controller {name!r} (choose from {', '.join(CONTROLLERS)})")
    return CONTROLLERS[name](camera, config)
