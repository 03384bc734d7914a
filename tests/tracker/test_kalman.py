"""The box filter's process noise against filterpy's own construction."""
import numpy as np
import pytest
from filterpy.common import Q_discrete_white_noise

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
