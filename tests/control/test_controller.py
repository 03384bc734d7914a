"""The rate controllers in a synthetic closed loop (tests/control/control_scene.py)."""
from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from control_scene import run_scene
from pipelines.control.camera import CameraModel
from pipelines.control.controller import (
    ControlConfig, ProportionalController, RateController, controller_names, make_controller,
)
from pipelines.control.direction import Direction, DirectionFilter, relative, wrap_deg
from pipelines.control.limits import PROTOCOL_MAX_SPEED_DPS, limit_rate
from tracker.runtime.estimate import TargetEstimate, TrackState


CAM = CameraModel(640, 360)
KEEPALIVE_MAX_AGE_S = 0.3  # the speed streamer sends zero instead of a setpoint this old


def ramp(t):
    return 20.0 * t, 5.0 * t


def sine(t):
    return 15.0 * math.sin(math.pi * t), 5.0 * math.sin(0.6 * math.pi * t)


def step(t):
    return (10.0 if t >= 1.0 else 0.0), 0.0


def pid():
    return make_controller("pid", camera=CAM)


def baseline():
    return make_controller("p", camera=CAM)


def rms(a):
    return float(np.sqrt(np.mean(np.square(a))))


@pytest.mark.parametrize("latency", [0.0, 0.1])
def test_ramp_steady_state_error_is_near_zero(latency):
    err = run_scene(pid(), ramp, 5.0, latency=latency).window("err", 2.0)
    p_err = run_scene(baseline(), ramp, 5.0, latency=latency).window("err", 2.0)
    assert err.max() < 0.3
    assert p_err.mean() > 5.0  # a P loop lags a ramp by rate / gain
    assert err.mean() < 0.05 * p_err.mean()


@pytest.mark.parametrize("latency", [0.0, 0.1])
def test_sine_rms_is_at_most_half_the_baseline(latency):
    err = run_scene(pid(), sine, 6.0, latency=latency, noise_px=1.0).window("err", 1.0)
    p_err = run_scene(baseline(), sine, 6.0, latency=latency, noise_px=1.0).window("err", 1.0)
    assert rms(err) < 0.5 * rms(p_err)


def test_step_settles_with_little_overshoot():
    tr = run_scene(pid(), step, 4.0)
    yaw_err = tr.window("yaw_err", 1.0)
    assert -yaw_err.min() < 0.1 * 10.0  # overshoot under 10 %
    assert np.abs(tr.window("yaw_err", 3.0)).max() < 0.5


class BlindController(RateController):
    """The same loop without latency compensation: the gimbal is taken to point where it did
    at capture, and the target is not extrapolated."""

    def _pointing(self, t: float) -> tuple[float, float]:
        return self._attitude[:2]


def test_latency_compensation_keeps_a_delayed_loop_damped():
    def overshoot(ctl):
        tr = run_scene(ctl, step, 4.0, latency=0.1)
        return -tr.window("yaw_err", 1.0).min()

    blind = BlindController(CAM, ControlConfig(actuation_delay_s=0.0, max_prediction_s=0.0))
    assert overshoot(pid()) < 0.5
    assert overshoot(blind) > 3.0  # the same gains without the predictor ring


@pytest.mark.parametrize("latency", [0.4, 0.6])
def test_latency_beyond_the_prediction_cap_is_still_compensated(latency):
    """max_prediction_s caps the target's extrapolation only: the predicted pointing still counts
    every setpoint sent, however long the capture-to-command latency (it once oscillated)."""
    tr = run_scene(pid(), step, 5.0, latency=latency)
    assert -tr.window("yaw_err", 1.0).min() < 1.0
    assert np.abs(tr.window("yaw_err", 3.5)).max() < 0.2


def test_a_ramp_beyond_the_prediction_cap_trails_by_the_held_part():
    """Beyond the cap the target is held where it was predicted at the cap: the gimbal trails a
    ramp by speed * (latency + actuation_delay_s - max_prediction_s), steadily."""
    cfg, latency = ControlConfig(), 0.6
    tr = run_scene(RateController(CAM, cfg), ramp, 6.0, latency=latency)
    held = math.hypot(20.0, 5.0) * (latency + cfg.actuation_delay_s - cfg.max_prediction_s)
    err = tr.window("err", 4.0)
    assert np.abs(err - held).max() < 0.15 * held


@pytest.mark.parametrize("latency", [0.0, 0.1])
def test_loss_stops_within_the_configured_time(latency):
    cfg = ControlConfig()
    tr = run_scene(RateController(CAM, cfg), lambda t: (40.0 * t, 0.0), 4.0, latency=latency,
                   hidden=lambda t: t >= 2.0)
    t, yaw, mode = tr.arr("cmd_t"), tr.arr("cmd_yaw"), tr.arr("mode")
    last_track = t[mode == "track"].max()
    assert yaw[t <= last_track].max() > 35.0  # it was following before the loss
    after = t > last_track + cfg.stop_within_s
    assert cfg.stop_within_s <= 0.3 + 1e-9
    assert np.all(yaw[after] == 0.0) and np.all(tr.arr("cmd_pitch")[after] == 0.0)
    assert set(mode[t > last_track]) <= {"hold", "ramp", "idle"}
    assert np.all(np.abs(np.diff(yaw[t > last_track])) <= cfg.max_accel_dps2 * (1 / 30) + 1e-9)
    assert abs(tr.window("gimbal_rate", 3.0)).max() < 1e-3  # and the gimbal stands still


def pan_across_a_stall(name: str, stall_s: float) -> list[tuple[float, float, float, float]]:
    """A 10 deg/s pan followed at 30 fps by a rate-integrating gimbal, no frame processed for
    ``stall_s`` from t = 1 s; as the keep-alive does, a setpoint over 0.3 s old is streamed as zero.
    Returns (time, error deg, commanded yaw, yaw streamed until then) per processed frame."""
    ctl = make_controller(name, camera=CAM)
    gimbal = cmd = sent_at = 0.0
    rows = []
    for k in range(1, int((4.0 + stall_s) * 30)):
        t = k / 30
        streamed = cmd if t - sent_at <= KEEPALIVE_MAX_AGE_S else 0.0
        gimbal += streamed / 30
        if 1.0 <= t < 1.0 + stall_s:
            continue
        offset = 10.0 * t - gimbal
        x = CAM.cx + CAM.focal_px * math.tan(math.radians(offset))
        est = TargetEstimate((x - 10, CAM.cy - 10, 20, 20), (0, 0), 0.9, TrackState.TRACKING, t, k)
        cmd, sent_at = ctl.update(est, (gimbal, 0.0), t).yaw_dps, t
        rows.append((t, offset, cmd, streamed))
    return rows


@pytest.mark.parametrize("name", ["pid", "p"])
@pytest.mark.parametrize("stall_s", [1.0, 1.9])
def test_after_a_frame_stall_the_gimbal_restarts_from_rest(name, stall_s):
    """A stall longer than the keep-alive's 0.3 s: the gimbal was told zero, so the first setpoint
    after it steps from zero by at most max_accel * first_step_s, not max_accel * stall."""
    cfg = ControlConfig()
    rows = pan_across_a_stall(name, stall_s)
    first = next(i for i, row in enumerate(rows) if row[0] >= 1.0 + stall_s)
    _, _, cmd, streamed = rows[first]
    assert streamed == 0.0 and rows[first - 1][2] > 5.0  # it was moving, then streamed zero
    assert 0.0 < cmd <= cfg.max_accel_dps2 * cfg.first_step_s + 1e-9
    after = np.array(rows[first:])
    assert np.all(np.abs(np.diff(after[:, 2])) <= cfg.max_accel_dps2 * np.diff(after[:, 0]) + 1e-9)


@pytest.mark.parametrize("stall_s", [1.0, 1.9])
def test_the_integral_does_not_wind_up_over_a_stall(stall_s):
    """The stall is not integrated: the integral once restarted at ki * error * stall (5-16 deg/s)
    and left a 0.5-1.3 deg offset 1.5 s after it; what remains is the catch-up's own (under 0.2)."""
    rows = np.array(pan_across_a_stall("pid", stall_s))
    assert np.abs(rows[rows[:, 0] >= 2.5 + stall_s, 1]).max() < 0.3


def test_no_estimate_at_all_after_tracking_stops_the_gimbal():
    ctl = pid()
    for i in range(30):
        t = i / 30
        box = (400.0 + 3 * i, 170.0, 20.0, 20.0)
        ctl.update(TargetEstimate(box, (0, 0), 0.9, TrackState.TRACKING, t, i), (0.0, 0.0), t)
    moving = ctl.update(None, None, 1.0).yaw_dps
    assert moving > 0
    cmds = [ctl.update(None, None, 1.0 + i / 30) for i in range(1, 30)]
    stopped = [c for c in cmds if c.yaw_dps == 0.0 and c.pitch_dps == 0.0]
    assert stopped and stopped[0].mode in {"ramp", "idle"}
    assert all(c.yaw_dps == 0.0 for c in cmds[cmds.index(stopped[0]):])
    assert (cmds.index(stopped[0]) + 2) / 30 <= 0.3 + 1e-9  # the last detection was at 29/30 s


def test_searching_holds_the_prediction_then_ramps_down():
    ctl = pid()
    for i in range(40):
        t = i / 30
        box = (300.0 + 2 * i, 170.0, 20.0, 20.0)
        ctl.update(TargetEstimate(box, (0, 0), 0.9, TrackState.TRACKING, t, i), (0.0, 0.0), t)
    modes = []
    for i in range(40, 60):
        t = i / 30
        est = TargetEstimate((380.0, 170.0, 20.0, 20.0), (0, 0), 0.2, TrackState.SEARCHING, t, i)
        modes.append(ctl.update(est, (0.0, 0.0), t).mode)
    assert modes[0] == "hold" and "ramp" in modes and modes[-1] == "idle"


def test_limits_hold_for_a_target_too_fast_to_follow():
    cfg = ControlConfig(max_speed_dps=90.0, max_accel_dps2=450.0)
    for ctl in (RateController(CAM, cfg), ProportionalController(CAM, cfg, gain_per_s=20.0)):
        tr = run_scene(ctl, lambda t: (200.0 * t, 60.0 * math.sin(3 * t)), 3.0, latency=0.05)
        yaw, pitch, t = tr.arr("cmd_yaw"), tr.arr("cmd_pitch"), tr.arr("cmd_t")
        assert np.abs(yaw).max() <= 90.0 and np.abs(pitch).max() <= 90.0
        for axis in (yaw, pitch):
            assert np.all(np.abs(np.diff(axis)) <= 450.0 * np.diff(t) + 1e-9)
        assert np.all(tr.arr("cmd_roll") == 0.0)


def test_yaw_wrap_does_not_upset_the_loop():
    tr = run_scene(pid(), lambda t: (170.0 + 20.0 * t, 0.0), 2.0)
    # the loop starts at yaw 0 facing a target at 170: lost at once, so start it facing the target
    assert np.all(tr.arr("cmd_yaw") == 0.0)
    ctl = pid()
    cmds = []
    for i in range(90):  # gimbal and target both cross +-180 deg
        t = i / 30
        yaw = ((175.0 + 20.0 * t) + 180.0) % 360.0 - 180.0
        est = TargetEstimate((310.0, 170.0, 20.0, 20.0), (0, 0), 0.9, TrackState.TRACKING, t, i)
        cmds.append(ctl.update(est, (yaw, 0.0), t))
    assert max(abs(c.yaw_dps) for c in cmds) < 30.0
    assert max(abs(c.yaw_error_deg) for c in cmds) < 2.0


class AttitudeFrom:
    """Hands the controller the attitude of the frames captured from ``start`` on, offset by
    ``offset`` (a gimbal whose zero is elsewhere), and none before (pushes not arrived yet)."""

    def __init__(self, start: float, offset: tuple[float, float] = (0.0, 0.0)) -> None:
        self.ctl, self.start, self.offset = pid(), start, offset

    def update(self, est, att, now):
        if est is None or est.timestamp < self.start:
            att = None
        elif att is not None:
            att = (att[0] + self.offset[0], att[1] + self.offset[1])
        return self.ctl.update(est, att, now)


def test_missing_attitude_is_dead_reckoned_from_the_setpoints():
    ctl = pid()

    class FirstAttitudeOnly:
        def update(self, est, att, now):
            att = att if now == 0.0 else None
            return ctl.update(est, att, now)

    err = run_scene(FirstAttitudeOnly(), ramp, 4.0, tau=0.02).window("err", 2.0)
    assert err.max() < 1.0


@pytest.mark.parametrize("duration", [4.0, 15.0])
def test_without_any_attitude_the_loop_follows_in_the_cameras_frame(duration):
    """No attitude ever (pushes that never arrive): the loop still follows, as without attitude
    feedback (it once stayed idle), better than the P baseline."""
    tr = run_scene(AttitudeFrom(math.inf), ramp, duration, tau=0.02)
    p_err = run_scene(baseline(), ramp, duration, tau=0.02).window("err", 2.0)
    assert set(tr.window("mode", 0.0)) == {"track"}
    assert tr.window("err", 2.0).max() < 3.0 and tr.window("err", 2.0).mean() < 0.5 * p_err.mean()


def test_without_any_attitude_a_gimbal_at_its_stop_is_never_turned_the_wrong_way():
    """Dead-reckoning from an assumed (0, 0) once grew past 90 deg of pitch against a gimbal held at
    its stop, and then sent the pitch the wrong way and spun the yaw for a subject straight ahead."""
    controller = RateController(CAM)
    yaw, pitch, subject = 0.0, 25.0, (0.0, 40.0)  # the gimbal stops at +35: the subject stays above
    for i in range(240):
        t = i / 30
        x, y = CAM.angles_to_pixel(*relative((yaw, pitch), subject))
        estimate = TargetEstimate((x - 20, y - 20, 40, 40), (0.0, 0.0), 1.0, TrackState.TRACKING, t, i)
        command = controller.update(estimate, None, t + 0.03)
        assert command.pitch_dps >= 0.0 and abs(command.yaw_dps) < 1e-6
        yaw, pitch = yaw + command.yaw_dps / 30, min(35.0, pitch + command.pitch_dps / 30)


def test_a_setpoint_the_keep_alive_has_zeroed_is_not_counted_in_the_pointing():
    """After a frame stall the Smith predictor once took the last setpoint as held through the stall
    (the keep-alive had sent zero after 0.3 s): a phantom error of ~10 deg on the first frame."""
    controller = RateController(CAM)
    for i in range(60):
        t = i / 30
        controller.update(TargetEstimate((310, 170, 20, 20), (0.0, 0.0), 1.0, TrackState.TRACKING, t, i),
                          (60.0 * t, 0.0), t)
    # one second later: the gimbal stopped at its last attitude, the subject is centred
    after = controller.update(TargetEstimate((310, 170, 20, 20), (0.0, 0.0), 1.0, TrackState.TRACKING, 3.0, 60),
                              (60.0 * 59 / 30 + 60.0 * 0.3, 0.0), 3.0)
    assert abs(after.yaw_error_deg) < 1.0


@pytest.mark.parametrize("offset", [(30.0, 0.0), (-120.0, 0.0)])
def test_the_first_measured_attitude_restarts_the_target_in_its_frame(offset):
    """The first attitude replaces the assumed zero: the target's filter restarts in the measured
    frame instead of seeing the whole difference as a jump of the target."""
    late = run_scene(AttitudeFrom(1.5, offset), sine, 4.0, latency=0.05, noise_px=1.0)
    measured = run_scene(pid(), sine, 4.0, latency=0.05, noise_px=1.0)
    assert late.window("err", 1.5, 2.5).max() < 1.2 * measured.window("err", 1.5, 2.5).max()


class AttitudeDropout:
    """No attitude for the frames captured in [t0, t1) (pushes lost), and a gimbal that moves at
    ``gain`` of every commanded speed, so the dead-reckoned pointing drifts meanwhile."""

    def __init__(self, t0: float, t1: float, gain: float) -> None:
        self.ctl, self.t0, self.t1, self.gain = pid(), t0, t1, gain

    def update(self, est, att, now):
        if est is not None and self.t0 <= est.timestamp < self.t1:
            att = None
        command = self.ctl.update(est, att, now)
        return dataclasses.replace(command, yaw_dps=command.yaw_dps * self.gain,
                                   pitch_dps=command.pitch_dps * self.gain)


@pytest.mark.parametrize("dropout_s", [1.0, 2.0])
def test_a_returning_attitude_is_not_taken_for_a_jump_of_the_target(dropout_s):
    """When the attitude returns, the target measured against the drifted dead-reckoning is moved
    by the drift: it was seen as a jump back (a subject panning at 30 deg/s got -5 to -14 deg/s
    and the error rose to 4.8-7.2 deg)."""
    tr = run_scene(AttitudeDropout(2.0, 2.0 + dropout_s, 0.8), lambda t: (30.0 * t, 0.0), 5.0 + dropout_s,
                   latency=0.05)
    after = 2.0 + dropout_s
    assert tr.window("cmd_yaw", after).min() > 10.0
    assert tr.window("err", after).max() < 3.0


def test_config_validation_and_factory():
    with pytest.raises(ValueError):
        ControlConfig(max_speed_dps=400.0)
    with pytest.raises(ValueError):  # 120 deg/s to zero in 0.1 s needs 1200 deg/s^2
        ControlConfig(ramp_s=0.1, max_accel_dps2=900.0)
    with pytest.raises(ValueError):
        ControlConfig(setpoint_max_age_s=0.0)
    assert controller_names() == ["pid", "p"]
    assert isinstance(make_controller(camera=CAM), RateController)
    assert isinstance(make_controller("p", camera=CAM), ProportionalController)
    with pytest.raises(ValueError):
        make_controller("lqr", camera=CAM)


def juggle(t, period=0.93, gravity=190.0):
    """A ball juggled in front of a slowly panning camera: parabolic arcs (gravity 190 deg/s^2
    seen from ~3 m) re-thrown every ``period`` s, the speed reversing at once at each catch."""
    s = t % period
    return -2.0 + 8.0 * t, -5.0 + gravity * period / 2 * s - 0.5 * gravity * s * s


@pytest.mark.parametrize("latency", [0.0, 0.1])
def test_juggled_ball_is_never_lost_and_is_not_chased(latency):
    tr = run_scene(pid(), juggle, 6.0, latency=latency, noise_px=1.0)
    p_err = run_scene(baseline(), juggle, 6.0, latency=latency, noise_px=1.0).window("err", 1.0)
    assert set(tr.window("mode", 0.5)) == {"track"}  # in view at every frame
    # matching the arcs' speed then reversing at 600 deg/s^2 overshoots by ~2 v^2 / a ~ 25 deg:
    # the trust keeps the loop from committing to it (trusting blindly was 2.2-2.5x worse than P)
    assert rms(tr.window("err", 1.0)) < 1.0 * rms(p_err)


def test_large_step_closes_fast_without_overshoot():
    tr = run_scene(pid(), lambda t: (25.0 if t >= 1.0 else 0.0, 0.0), 4.0)
    yaw_err = tr.window("yaw_err", 1.0)
    assert -yaw_err.min() < 0.1 * 25.0
    t = tr.arr("t")[tr.arr("t") >= 1.0]
    assert t[np.argmax(np.abs(yaw_err) < 1.0)] - 1.0 < 0.6  # within 1 deg in under 0.6 s


@pytest.mark.parametrize("size", [10.0, 20.0])
def test_the_integral_does_not_grow_while_a_large_step_closes_at_braking_speed(size):
    """The shaper sets the closing speed of a large error; integrating it meanwhile overshot and
    left a slowly decaying offset (20 deg: 0.18 deg over, -0.16 deg at 2-3 s; 10 deg: -0.11)."""
    tr = run_scene(pid(), lambda t: (size if t >= 1.0 else 0.0, 0.0), 3.0)
    assert -tr.window("yaw_err", 1.0).min() < 0.1
    assert abs(tr.window("yaw_err", 2.0, 3.0).mean()) < 0.09


def test_the_first_detection_is_acted_on_within_the_acceleration_limit():
    cfg = ControlConfig()
    est = TargetEstimate((500.0, 170.0, 20.0, 20.0), (0, 0), 0.9, TrackState.TRACKING, 0.0, 0)
    first = RateController(CAM, cfg).update(est, (0.0, 0.0), 0.004)
    assert first.mode == "track"
    assert 0.0 < first.yaw_dps <= cfg.max_accel_dps2 * cfg.first_step_s + 1e-9
    assert first.pitch_dps == 0.0 and first.roll_dps == 0.0
    with pytest.raises(ValueError):
        ControlConfig(first_step_s=0.0)


@pytest.mark.parametrize("name", ["pid", "p"])
def test_a_nan_box_is_never_steered_by(name):
    """min/max turn NaN into the limit: a NaN centre once drove these controllers to full speed."""
    ctl = make_controller(name, camera=CAM)
    centred = (310.0, 170.0, 20.0, 20.0)  # the image centre: nothing to correct
    cmds = []
    for i in range(60):
        box = (float("nan"),) * 4 if 10 <= i < 13 else centred
        t = i / 30
        cmds.append(ctl.update(TargetEstimate(box, (0, 0), 0.9, TrackState.TRACKING, t, i), (0.0, 0.0), t))
    rates = np.array([(c.yaw_dps, c.pitch_dps) for c in cmds])
    assert np.isfinite(rates).all() and np.abs(rates).max() < 1.0


# What the P baseline's setpoints report besides the speeds: signed errors and latency.


def test_errors_follow_the_cameras_angle_convention_and_latency_is_now_minus_capture() -> None:
    """A target up and to the right: yaw and pitch errors are the camera's angles of its centre
    (both positive), and the latency is the time since the frame's capture."""
    controller = ProportionalController(CAM)
    box = (390.0, 90.0, 20.0, 20.0)  # centre (400, 100): right of and above (320, 180)
    controller.update(TargetEstimate(box, (0.0, 0.0), 0.9, TrackState.TRACKING, 0.0, 0), None, 0.01)
    command = controller.update(TargetEstimate(box, (0.0, 0.0), 0.9, TrackState.TRACKING, 1 / 30, 1), None, 0.05)
    assert (command.yaw_error_deg, command.pitch_error_deg) == pytest.approx(CAM.pixel_to_angles(400.0, 100.0))
    assert command.pitch_error_deg > 0.0 and command.yaw_error_deg > 0.0
    assert command.yaw_dps > 0.0 and command.pitch_dps > 0.0
    assert command.latency_s == pytest.approx(0.05 - 1 / 30)
    assert command.stamp == pytest.approx(1 / 30)


# The PID's integral share of a setpoint is capped by ``integral_limit_dps``.


def test_a_gimbal_held_at_its_stop_does_not_wind_the_integral_past_its_limit() -> None:
    """The subject stays 3 deg right of a gimbal that cannot move: the error never closes, and the
    setpoint grows by the integral only up to ``integral_limit_dps`` over the proportional part."""
    cfg = ControlConfig(ki=4.0, integral_limit_dps=5.0)
    controller = RateController(CAM, cfg)
    x, _ = CAM.angles_to_pixel(3.0, 0.0)
    for i in range(150):
        t = i / 30
        estimate = TargetEstimate((x - 10.0, 170.0, 20.0, 20.0), (0.0, 0.0), 0.9, TrackState.TRACKING, t, i)
        command = controller.update(estimate, (0.0, 0.0), t)
        proportional = cfg.kp * (command.yaw_error_deg - cfg.deadband_deg)
        assert command.yaw_dps <= proportional + cfg.integral_limit_dps + 1e-6
    assert command.yaw_dps > proportional + 0.99 * cfg.integral_limit_dps  # it did reach the limit


# A NaN control setting, a camera size that is no whole number of pixels, a NaN or infinite
# focal length, and a controller clock that is not finite or runs backwards are refused by name
# (they were accepted and later a 'cannot clamp NaN' or a silent zero output, e.g. feedforward=NaN).
ESTIMATE = TargetEstimate(box=(400.0, 200.0, 40.0, 40.0), velocity=(0.0, 0.0), confidence=0.9,
                          state=TrackState.TRACKING, timestamp=0.0, frame_index=1)


@pytest.mark.parametrize("name", [f.name for f in dataclasses.fields(ControlConfig)])
def test_a_nan_setting_is_refused_by_name(name: str) -> None:
    with pytest.raises(ValueError, match=f"ControlConfig.{name} must be a number, not nan"):
        ControlConfig(**{name: math.nan})


@pytest.mark.parametrize("size", [(math.nan, 360), (640.5, 360), (None, 360), (640, True)])
def test_a_camera_size_must_be_whole_pixels(size) -> None:
    with pytest.raises(ValueError, match="whole pixels"):
        CameraModel(*size)


@pytest.mark.parametrize("focal", [math.nan, math.inf])
def test_a_focal_length_must_be_finite(focal: float) -> None:
    with pytest.raises(ValueError, match="focal_px must be positive and finite"):
        CameraModel(640, 360, focal_px=focal)


@pytest.mark.parametrize("name", ["pid", "p"])
@pytest.mark.parametrize("times", [(math.nan,), (1.0, math.inf), (1.0, 0.5)])
def test_the_clock_must_be_finite_and_not_run_backwards(name: str, times: tuple[float, ...]) -> None:
    controller = make_controller(name, camera=CAM)
    *before, bad = times
    for now in before:
        controller.update(ESTIMATE, (0.0, 0.0), now)
    with pytest.raises(ValueError, match=f"now={bad!r} must be a finite time"):
        controller.update(ESTIMATE, (0.0, 0.0), bad)


# ``limit_rate`` on a missing setpoint and on limits beyond the protocol's speed range.
def test_a_nan_setpoint_counts_as_exactly_zero() -> None:
    assert limit_rate(0.5, math.nan, 100.0, 100.0, 0.1) == 0.0
    assert limit_rate(-3.0, math.nan, 100.0, 100.0, 0.1) == 0.0
    assert limit_rate(0.0, math.nan, 100.0, 100.0, 0.1) == 0.0


@pytest.mark.parametrize("wanted", [1000.0, -1000.0])
def test_the_protocol_range_caps_a_larger_speed_limit(wanted: float) -> None:
    """The DJI R SDK speed command stops at 360 deg/s whatever limit a caller passes."""
    assert PROTOCOL_MAX_SPEED_DPS == 360.0
    assert limit_rate(0.0, wanted, 500.0, math.inf, 1.0) == math.copysign(360.0, wanted)


def test_the_speed_range_holds_even_when_the_previous_setpoint_was_outside_it() -> None:
    """A setpoint is never outside +-max_speed, even when that takes a step beyond ``max_accel * dt``
    (a previous setpoint sent under a higher limit)."""
    assert limit_rate(200.0, 200.0, 120.0, 600.0, 0.02) == 120.0
    assert limit_rate(-400.0, -50.0, 500.0, 600.0, 0.02) == -360.0


# A target found again after the controller stopped is filtered and controlled afresh.


def _seen(x: float, t: float, index: int) -> TargetEstimate:
    return TargetEstimate((x - 10.0, 170.0, 20.0, 20.0), (0.0, 0.0), 0.9, TrackState.TRACKING, t, index)


def test_a_still_centred_target_found_after_a_loss_is_not_chased_with_the_old_motion() -> None:
    """A subject panning at ~45 deg/s is lost for 1 s (over ``stop_within_s``), then found standing
    still at the centre: no speed of the old pan (filter velocity, integral) may reach the gimbal."""
    controller = RateController(CAM)
    assert ControlConfig().stop_within_s < 1.0
    for i in range(30):
        controller.update(_seen(320.0 + 8.0 * i, i / 30, i), (0.0, 0.0), i / 30)
    for i in range(30, 60):
        assert controller.update(None, None, i / 30).mode in {"hold", "ramp", "idle"}
    for i in range(60, 75):
        command = controller.update(_seen(320.0, i / 30, i), (0.0, 0.0), i / 30)
        assert command.mode == "track"
        assert abs(command.yaw_dps) < 0.05 and abs(command.pitch_dps) < 0.05


# Yaw errors and commands when the gimbal and an off-centre target straddle +-180 deg.


def test_an_off_centre_target_across_the_wrap_keeps_a_small_error_and_the_same_direction() -> None:
    """The gimbal pans through 180 deg with the target 20 px right of the centre (~2.2 deg): for the
    frames where one is past the wrap and the other not, the error is not ~360 deg and the gimbal
    is not sent the other way."""
    controller = RateController(CAM)
    for i in range(90):
        t = i / 30
        attitude = (wrap_deg(170.0 + 10.0 * t), 0.0)
        estimate = TargetEstimate((330.0, 170.0, 20.0, 20.0), (0.0, 0.0), 0.9, TrackState.TRACKING, t, i)
        command = controller.update(estimate, attitude, t)
        assert abs(command.yaw_error_deg) < 5.0
        assert command.yaw_dps >= 0.0


def test_the_filtered_yaw_is_wrapped() -> None:
    """The filter keeps yaw unwrapped inside; what it hands out is in [-180, 180)."""
    kf = DirectionFilter()
    for i in range(90):
        t = i / 30
        d = kf.update((wrap_deg(170.0 + 30.0 * t), 0.0), t)
        assert -180.0 <= d.yaw < 180.0
    assert d.yaw == pytest.approx(wrap_deg(170.0 + 30.0 * 89 / 30), abs=0.5)


def test_extrapolation_wraps_the_yaw() -> None:
    assert Direction(175.0, 2.0, 20.0, -1.0, 1.0).at(1.5) == pytest.approx((-175.0, 1.5))
    assert Direction(-175.0, 0.0, -20.0, 0.0, 0.0).at(0.5) == pytest.approx((175.0, 0.0))
