"""Measured behaviour: the 0.5 s rule, push rate, limits, release, and the axis model itself."""
from __future__ import annotations

import time
from collections import Counter

import pytest

from gimbal.errors import ReturnCodeError
from gimbal.messages import external, motion, settings, telemetry
from gimbal.messages.telemetry import PUSH_DISABLE, PUSH_ENABLE, PushControl
from gimbal.sim import SimConfig
from gimbal.sim.dynamics import Axis, AxisRange
from gimbal.sim.model import GimbalModel
from tests.sim.helpers import wait_until


def stop_time_after(sim, sent_at: float) -> float:  # type: ignore[no-untyped-def]
    """Seconds from ``sent_at`` to the first snapshot at rest."""
    assert wait_until(lambda: sim.state().moving, 0.2, step=0.002)
    while sim.state().moving:
        time.sleep(0.002)
    return sim.state().time - sent_at


def test_half_second_rule_measured(make_client) -> None:
    client, sim = make_client()
    sent_at = time.monotonic()
    client.speed(20.0, 0.0)
    stopped = stop_time_after(sim, sent_at)
    assert 0.5 <= stopped <= 0.6, stopped
    print(f"0.5 s rule: stopped {stopped:.3f} s after the last speed command")


def test_zero_speed_stops_at_once_and_release_stops(make_client) -> None:
    client, sim = make_client()
    client.speed(36.0, 0.0)
    time.sleep(0.1)
    sent_at = time.monotonic()
    client.speed(0.0, 0.0)
    assert stop_time_after(sim, sent_at) < 0.1  # 36 °/s at 720 °/s² takes 50 ms
    client.speed(36.0, 0.0)
    time.sleep(0.1)
    sent_at = time.monotonic()
    client.speed(36.0, 0.0, take_control=False)
    assert stop_time_after(sim, sent_at) < 0.1
    assert not sim.state().speed_control


@pytest.mark.parametrize("rate", [50.0, 20.0])
def test_push_rate_within_ten_percent(make_client, rate: float) -> None:
    client, sim = make_client(SimConfig(push_rate_hz=rate))
    arrivals: list[float] = []
    client.on_push(telemetry.ParameterPush, lambda m, t: arrivals.append(t))
    client.set_push(True)
    time.sleep(1.2)
    client.set_push(False)
    window = [t for t in arrivals if arrivals[0] + 0.1 <= t <= arrivals[0] + 1.1]
    measured = (len(window) - 1) / (window[-1] - window[0])
    assert abs(measured - rate) <= 0.1 * rate, measured
    print(f"push rate: configured {rate} Hz, measured {measured:.1f} Hz")


def test_position_beyond_limits_is_refused(make_client) -> None:
    client, sim = make_client()
    client.set_angle_limits(pitch_max=30, pitch_min=20, yaw_max=90, yaw_min=90, roll_max=30, roll_min=30)
    for yaw, pitch in ((100.0, 0.0), (0.0, 35.0), (0.0, -25.0)):
        with pytest.raises(ReturnCodeError) as err:
            client.position(yaw, 0.0, pitch, time_s=0.2)
        assert err.value.return_code == 0x02
    client.position(80.0, 0.0, 0.0, time_s=0.2)
    assert wait_until(lambda: sim.state().joint[0] == 80.0, 1.0)
    with pytest.raises(ReturnCodeError):
        client.position(20.0, 0.0, 0.0, absolute=False, time_s=0.2)  # relative: 100° > 90°
    client.position(0.0, 0.0, 0.0, axes=("roll",), time_s=0.1)  # yaw flagged invalid: stays
    time.sleep(0.2)
    assert sim.state().joint[0] == 80.0


def test_speed_stops_at_the_limit_and_new_limits_pull_back(make_client) -> None:
    client, sim = make_client(SimConfig(initial_joint_deg=(0.0, 0.0, 40.0)))
    client.set_angle_limits(pitch_max=45, pitch_min=55, yaw_max=179, yaw_min=179, roll_max=30, roll_min=30)
    client.speed(0.0, 100.0)
    time.sleep(0.2)
    state = sim.state()
    assert state.joint[2] == 45.0 and state.speeds[2] == 0.0
    client.set_angle_limits(pitch_max=10, pitch_min=55, yaw_max=179, yaw_min=179, roll_max=30, roll_min=30)
    assert wait_until(lambda: sim.state().joint[2] == 10.0, 1.0)


def test_new_limits_pull_the_axis_back_at_the_recenter_speed() -> None:
    """The axis moves back at 100 deg/s, as docs/simulator.md says; it once snapped to the new limit."""
    model = GimbalModel(SimConfig(initial_joint_deg=(0.0, 0.0, 40.0)), 0.0)
    model.handle(settings.SetAngleLimits(pitch_max=10, pitch_min=55, yaw_max=179, yaw_min=179,
                                         roll_max=30, roll_min=30), 0.0)
    model.advance(0.1)
    assert model.joint()[2] == pytest.approx(30.0)
    model.advance(0.3)
    assert model.joint()[2] == pytest.approx(10.0)


def test_mechanical_ranges_and_continuous_yaw() -> None:
    model = GimbalModel(SimConfig(yaw_continuous=True), 0.0)
    assert model.handle(motion.PositionControl(0, 0, 1460, 1, 0), 0.0).return_code == 0x02  # > 145° limit
    assert model.handle(motion.PositionControl(0, 0, 1450, 1, 0), 0.0).ok
    assert model.handle(motion.PositionControl(0, 300, 0, 0x09, 0), 0.0).ok  # +30° roll, pitch invalid
    model.advance(1.0)
    assert model.joint() == (0.0, 30.0, 145.0)
    assert model.handle(motion.PositionControl(1700, 0, 0, 0x0D, 0), 1.0).ok
    model.advance(2.0)
    assert model.handle(motion.PositionControl(200, 0, 0, 0x0C, 10), 2.0).ok  # +20° relative
    model.advance(2.5)
    assert model.joint()[0] == pytest.approx(-180.0)  # wrapped through +180
    model.advance(3.0)
    assert model.joint()[0] == pytest.approx(-170.0)


def test_axis_acceleration_and_expiry_are_exact() -> None:
    axis = Axis(0.0, max_speed=360.0, accel=720.0)
    free = AxisRange(-180.0, 180.0)
    axis.advance(0.0, free)
    axis.set_speed(72.0, 0.0, hold_for=0.5)
    axis.advance(0.05, free)
    assert axis.velocity == pytest.approx(36.0) and axis.angle == pytest.approx(0.9)
    axis.advance(0.5, free)
    assert axis.velocity == pytest.approx(72.0)
    axis.advance(0.55, free)
    assert axis.velocity == pytest.approx(36.0)
    axis.advance(0.6, free)
    assert axis.velocity == 0.0 and axis.mode.value == "hold"
    assert axis.angle == pytest.approx(0.5 * 72.0 * 0.1 + 72.0 * 0.4 + 0.5 * 72.0 * 0.1)


def test_the_model_is_exact_whenever_it_is_asked_without_being_advanced() -> None:
    """Commands and queries integrate up to their own time first: a speed command after an idle
    second does not move the gimbal over that second, and a query sees the motion since."""
    model = GimbalModel(SimConfig(), 0.0)
    assert model.handle(motion.SpeedControl(yaw_speed=100), 1.0).ok  # 10 °/s yaw
    reply = model.handle(motion.GetAngles(motion.ANGLES_JOINT), 1.4)
    ramp = 10.0 / 720.0  # seconds to reach 10 °/s
    assert reply.yaw == round(10 * (0.4 - ramp / 2) * 10)  # 0.1° units: not 0, and not over 1.4 s
    assert model.snapshot(1.9, Counter(), Counter()).speeds[0] == 0.0  # expired at 1.5 s, decelerated


def test_a_dial_push_drives_the_focus_for_its_half_second_exactly() -> None:
    model = GimbalModel(SimConfig(focus_speed=1000.0), 0.0)
    model.apply_push(external.DialPush(dial_speed=1024), 0.0)  # half speed for 0.5 s
    model.advance(2.0)  # one long step past the push's expiry
    assert model.focus.position == pytest.approx(250.0)


def test_the_tick_thread_sleeps_until_something_is_due(make_client) -> None:
    """An idle simulator does not poll; with the push on it wakes about once a push."""
    client, sim = make_client()
    calls = []
    advance = sim._model.advance
    sim._model.advance = lambda now: calls.append(now) or advance(now)  # type: ignore[method-assign]
    time.sleep(0.5)
    assert len(calls) <= 2, len(calls)  # was 100 at the 200 Hz tick
    client.set_push(True)
    time.sleep(0.5)
    assert 20 <= len(calls) <= 32, len(calls)  # 25 pushes at 50 Hz, plus the wake for the command


# Re-enabling the parameter push (0x07) restarts its schedule: one push at once, then one a period.
def push_times(model: GimbalModel, start: float, end: float, step: float = 0.001) -> list[float]:
    """Times (to ``step``) at which ``advance`` returned a parameter push."""
    times, now = [], start
    while now <= end + 1e-9:
        if any(isinstance(m, telemetry.ParameterPush) for m in model.advance(now)):
            times.append(round(now, 3))
        now += step
    return times


def test_a_push_re_enabled_long_after_it_was_disabled_keeps_the_configured_period() -> None:
    """No catch-up burst: after 4 s off, the pushes are again 20 ms apart (50 Hz), the first at once."""
    model = GimbalModel(SimConfig(push_rate_hz=50.0), 0.0)
    assert model.handle(PushControl(PUSH_ENABLE), 0.0).ok
    push_times(model, 0.0, 1.0)
    assert model.handle(PushControl(PUSH_DISABLE), 1.0).ok
    assert push_times(model, 1.0, 5.0, step=0.01) == []
    assert model.handle(PushControl(PUSH_ENABLE), 5.0).ok
    times = push_times(model, 5.0, 5.1)
    assert times[0] == 5.0
    gaps = [round(b - a, 3) for a, b in zip(times, times[1:])]
    assert gaps and all(abs(g - 0.02) <= 0.0015 for g in gaps), gaps


def test_a_late_advance_sends_one_catch_up_push_not_a_burst() -> None:
    """The tick thread woken 200 ms late at 50 Hz: at most one extra push, then 20 ms apart again."""
    model = GimbalModel(SimConfig(push_rate_hz=50.0), 0.0)
    assert model.handle(PushControl(PUSH_ENABLE), 0.0).ok
    assert push_times(model, 0.0, 0.0) == [0.0]
    times = push_times(model, 0.2, 0.26)
    assert times[0] == 0.2 and len(times) <= 5, times
    assert all(b - a >= 0.019 for a, b in zip(times[2:], times[3:])), times


# Commanded speeds never exceed ``max_speed_dps`` (speed control and joystick alike).
def test_speed_control_above_the_maximum_is_held_to_it() -> None:
    """200 °/s asked of a 100 °/s gimbal: it turns at 100 °/s (after the 720 °/s² ramp)."""
    model = GimbalModel(SimConfig(max_speed_dps=100.0), 0.0)
    assert model.handle(motion.SpeedControl(yaw_speed=2000, pitch_speed=-2000), 0.0).ok
    state = model.snapshot(0.3, Counter(), Counter())
    assert state.speeds[0] == pytest.approx(100.0) and state.speeds[2] == pytest.approx(-100.0)


def test_a_full_scale_joystick_beyond_the_maximum_is_held_to_it() -> None:
    """Joystick full scale 150 °/s on a 100 °/s gimbal: full deflection gives 100 °/s."""
    model = GimbalModel(SimConfig(max_speed_dps=100.0), 0.0)
    model.apply_push(external.JoystickPush(yaw_speed=external.JOYSTICK_RANGE[1]), 0.0)
    assert model.snapshot(0.4, Counter(), Counter()).speeds[0] == pytest.approx(100.0)


# Speed control toward the negative side stops at the lower (min) limits, as it does at the max.
def test_negative_pitch_speed_stops_at_the_user_pitch_min() -> None:
    """-100 °/s from -40° with pitch_min 45: held at -45°, at rest, not past the limit."""
    model = GimbalModel(SimConfig(initial_joint_deg=(0.0, 0.0, -40.0)), 0.0)
    limits = settings.SetAngleLimits(pitch_max=145, pitch_min=45, yaw_max=179, yaw_min=179,
                                     roll_max=30, roll_min=30)
    assert model.handle(limits, 0.0).ok
    assert model.handle(motion.SpeedControl(pitch_speed=-1000), 0.0).ok
    state = model.snapshot(0.3, Counter(), Counter())
    assert state.joint[2] == -45.0 and state.speeds[2] == 0.0


def test_negative_yaw_and_roll_speeds_stop_at_the_default_min_limits() -> None:
    """Default limits: yaw −179°, roll −30°; a 0.5 s command that would overshoot stops there."""
    model = GimbalModel(SimConfig(initial_joint_deg=(-170.0, -20.0, 0.0)), 0.0)
    assert model.handle(motion.SpeedControl(yaw_speed=-1000, roll_speed=-1000), 0.0).ok
    state = model.snapshot(0.4, Counter(), Counter())
    assert state.joint[:2] == (-179.0, -30.0)
    assert state.speeds[:2] == (0.0, 0.0)
