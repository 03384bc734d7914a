"""The box filter's process noise against filterpy's own construction."""
import numpy as np
import pytest
from filterpy.common import Q_discrete_white_noise

from tracker.runtime.boxes import center
from tracker.runtime.kalman import BoxKalman, white_noise_q


@pytest.mark.parametrize("dt, var", [(1 / 30, 1.0), (0.004, 9e4), (0.5, 2.5)])
def test_white_noise_q_is_filterpys_discrete_model(dt: float, var: float) -> None:
    np.testing.assert_allclose(white_noise_q(dt, var), Q_discrete_white_noise(dim=2, dt=dt, var=var), rtol=1e-12)


def test_box_filter_grows_its_covariance_by_the_per_axis_noise() -> None:
    """State cx, cy, vx, vy, w, h: the centre's noise pairs cx with vx and cy with vy."""
    kalman = BoxKalman(accel=100.0, size_rate=0.5)
    kalman.reset((10.0, 20.0, 40.0, 10.0), timestamp=0.0)
    before = kalman._kf.P.copy()
    dt, size = 0.05, 20.0  # sqrt(40 x 10)
    kalman.predict(dt)
    f = np.eye(6)
    f[0, 2] = f[1, 3] = dt
    q = np.zeros((6, 6))
    q[:4, :4] = Q_discrete_white_noise(dim=2, dt=dt, var=(100.0 * size) ** 2, block_size=2, order_by_dim=False)
    q[4, 4] = q[5, 5] = (0.5 * size) ** 2 * dt
    np.testing.assert_allclose(kalman._kf.P, f @ before @ f.T + q, rtol=1e-12)


# The box filter's start, its stop on a loss and how hard a measurement pulls it.
def _moving_filter() -> BoxKalman:
    """A filter that has followed a box moving 3 px a frame to the right for a second."""
    kalman = BoxKalman()
    kalman.reset((100.0, 50.0, 20.0, 20.0), 0.0)
    for i in range(1, 31):
        kalman.predict(i / 30)
        kalman.correct((100.0 + 3.0 * i, 50.0, 20.0, 20.0))
    assert kalman.velocity[0] == pytest.approx(90.0, rel=0.1)
    return kalman


def test_reset_starts_at_the_box_standing_still() -> None:
    kalman = _moving_filter()
    kalman.reset((10.0, 20.0, 40.0, 30.0), 2.0)
    assert kalman.box == pytest.approx((10.0, 20.0, 40.0, 30.0))
    assert kalman.velocity == (0.0, 0.0)
    assert kalman.predict(2.5) == pytest.approx((10.0, 20.0, 40.0, 30.0))


def test_stop_forgets_the_velocity_so_the_box_does_not_drift() -> None:
    kalman = _moving_filter()
    kalman.stop()
    held = kalman.box
    assert kalman.velocity == (0.0, 0.0)
    assert kalman.predict(2.0) == pytest.approx(held)


@pytest.mark.parametrize("scale", [1.0, 10.0])
def test_the_first_correction_pulls_by_the_same_share_at_any_box_size(scale: float) -> None:
    """Noise scales with the box: a shift of a tenth of the box moves a 20 px and a 200 px box by
    the same share of it (the start's uncertainty is in box sizes too)."""
    kalman = BoxKalman()
    kalman.reset((0.0, 0.0, 20.0 * scale, 20.0 * scale), 0.0)
    kalman.correct((2.0 * scale, 0.0, 20.0 * scale, 20.0 * scale))
    moved = center(kalman.box)[0] - 10.0 * scale
    assert moved / scale == pytest.approx(2.0 * 0.01 / (0.01 + 0.02 ** 2))


def test_a_zero_confidence_measurement_barely_moves_the_box() -> None:
    kalman = BoxKalman()
    kalman.reset((0.0, 0.0, 20.0, 20.0), 0.0)
    kalman.correct((50.0, 50.0, 20.0, 20.0), confidence=0.0)
    assert center(kalman.box) == pytest.approx((10.0, 10.0), abs=0.1)


def test_a_collapsed_measurement_keeps_the_box_at_least_one_pixel_a_side() -> None:
    kalman = BoxKalman()
    kalman.reset((0.0, 0.0, 2.0, 2.0), 0.0)
    for _ in range(5):
        box = kalman.correct((0.0, 0.0, 0.0, 0.0))
    assert box[2] >= 1.0 and box[3] >= 1.0


def test_a_prediction_for_an_earlier_time_does_not_take_the_filter_back() -> None:
    """A late, older timestamp predicts nothing; the next prediction still starts from the latest."""
    once, twice = _moving_filter(), _moving_filter()
    expected = once.predict(1.5)
    twice.predict(1.5)
    assert twice.predict(1.2) == pytest.approx(expected)
    assert twice.predict(1.5) == pytest.approx(expected)
