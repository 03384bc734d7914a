import math

import pytest
from hypothesis import given, strategies as st

from pipelines.control.direction import DirectionFilter, PredictionTrust, compose, relative, wrap_deg


angles = st.floats(-179.9, 179.9)
pitches = st.floats(-80, 80)


def test_wrap():
    assert wrap_deg(180.0) == -180.0
    assert wrap_deg(-181.0) == pytest.approx(179.0)
    assert wrap_deg(541.0) == pytest.approx(-179.0)


def test_compose_level_gimbal_adds_yaw_across_the_wrap():
    assert compose((0.0, 0.0), (12.0, -7.0)) == pytest.approx((12.0, -7.0))
    assert compose((179.0, 0.0), (3.0, 0.0)) == pytest.approx((-178.0, 0.0))
    assert compose((-178.0, 0.0), (-4.0, 2.0)) == pytest.approx((178.0, 2.0))


def test_compose_pitched_gimbal_is_not_a_plain_sum():
    # looking 60 deg up, a target 10 deg right in the image is ~20 deg of world yaw away
    yaw, pitch = compose((0.0, 60.0), (10.0, 0.0))
    assert yaw == pytest.approx(math.degrees(math.atan(math.tan(math.radians(10)) / math.cos(math.radians(60)))))
    assert pitch < 60.0


@given(angles, pitches, st.floats(-60, 60), st.floats(-60, 60))
def test_relative_inverts_compose(gy, gp, oy, op):
    world = compose((gy, gp), (oy, op))
    assert relative((gy, gp), world) == pytest.approx((oy, op), abs=1e-6)


def test_filter_follows_a_ramp_across_the_wrap_without_a_jump():
    kf = DirectionFilter()
    assert kf.update(None, 0.0) is None  # nothing to predict from yet
    for i in range(90):
        t = i / 30
        d = kf.update((wrap_deg(170.0 + 30.0 * t), -5.0 + 6.0 * t), t)
        assert abs(wrap_deg(d.yaw - (170.0 + 30.0 * t))) < 0.5
    assert d.yaw_rate == pytest.approx(30.0, abs=0.5)
    assert d.pitch_rate == pytest.approx(6.0, abs=0.5)


def test_update_none_only_predicts():
    kf = DirectionFilter()
    for i in range(60):
        d = kf.update((10.0 * i / 30, 0.0), i / 30)
    before = kf._kf.P.trace()
    p = kf.update(None, d.timestamp + 0.5)
    assert p.yaw == pytest.approx(d.yaw + d.yaw_rate * 0.5, abs=1e-6)
    assert p.yaw_rate == pytest.approx(d.yaw_rate)
    assert kf._kf.P.trace() > before  # uncertainty grows, no measurement folded in
    assert d.at(d.timestamp + 0.5) == pytest.approx((p.yaw, p.pitch))


def _zigzag(t):
    """10 deg back and forth, reversing every 0.2 s."""
    return abs((t * 5.0) % 2.0 - 1.0) * 10.0, 0.0


def _trust_after(path, horizon=0.1, frames=90):
    kf, trust = DirectionFilter(), PredictionTrust()
    for i in range(frames):
        t = i / 30
        z = path(t)
        trust.observe(z, t, horizon)
        trust.add(kf.update(z, t))
    return trust.weight


def test_prediction_trust_is_high_for_smooth_motion_and_low_for_reversals():
    assert PredictionTrust().weight == 1.0  # it starts trusting
    assert _trust_after(lambda t: (30.0 * t, -5.0 + 6.0 * t)) > 0.95
    assert _trust_after(lambda t: (15.0 * math.sin(math.pi * t), 0.0)) > 0.8
    assert _trust_after(_zigzag) < 0.4  # over 0.1 s the extrapolation is wrong half the time


def test_prediction_trust_reset_forgets():
    trust = PredictionTrust()
    kf = DirectionFilter()
    for i in range(60):
        t = i / 30
        z = _zigzag(t)
        trust.observe(z, t, 0.1)
        trust.add(kf.update(z, t))
    assert trust.weight < 0.5
    trust.reset()
    assert trust.weight == 1.0


# The direction filter's measurement noise is a variance of ``measurement_std_deg`` squared.
@pytest.mark.parametrize("std", [0.15, 2.0])
def test_a_second_measurement_at_the_same_instant_is_averaged_with_the_first(std: float) -> None:
    """The start takes the first measurement with its noise (variance std**2); a second one at the
    same time, as noisy, carries equal weight: the estimate lands half way."""
    kf = DirectionFilter(measurement_std_deg=std)
    kf.update((10.0, -4.0), 1.0)
    d = kf.update((11.0, -3.0), 1.0)
    assert (d.yaw, d.pitch) == pytest.approx((10.5, -3.5))
    assert d.timestamp == 1.0


def test_an_older_measurement_does_not_take_the_state_back_in_time() -> None:
    kf = DirectionFilter()
    kf.update((10.0, 0.0), 1.0)
    assert kf.update((10.0, 0.0), 0.5).timestamp == 1.0
