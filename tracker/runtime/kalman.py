"""Constant-velocity Kalman filter on the box centre, random-walk size (filterpy)."""
from __future__ import annotations

import numpy as np
from filterpy.kalman import KalmanFilter

from tracker.runtime.boxes import Box, center, from_center

# State: cx, cy, vx, vy, w, h (pixels, pixels per second). Measurement: cx, cy, w, h.
_MEASURE = np.array([[1, 0, 0, 0, 0, 0], [0, 1, 0, 0, 0, 0], [0, 0, 0, 0, 1, 0], [0, 0, 0, 0, 0, 1]], float)


class BoxKalman:
    """Smooths measured boxes and predicts them forward in time.

    Noise scales with the box size, so one setting serves small and large subjects:
    ``accel`` is the centre's acceleration noise and ``size_rate`` the size's random-walk
    noise, both in box sizes per second (squared, resp. square-rooted); ``measurement`` is
    a confident measurement's noise in box sizes, inflated as confidence drops.
    """

    def __init__(self, accel: float = 100.0, size_rate: float = 0.5, measurement: float = 0.02) -> None:
        self.accel = accel
        self.size_rate = size_rate
        self.measurement = measurement
        self._kf = KalmanFilter(dim_x=6, dim_z=4)
        self._kf.H = _MEASURE
        self._time = 0.0

    def reset(self, box: Box, timestamp: float) -> None:
        """Start at ``box`` with zero velocity."""
        cx, cy = center(box)
        size = _size(box)
        self._kf.x = np.array([cx, cy, 0.0, 0.0, box[2], box[3]], float)
        self._kf.P = np.diag([0.01, 0.01, 4.0, 4.0, 0.01, 0.01]) * size**2
        self._time = timestamp

    def predict(self, timestamp: float) -> Box:
        """Advance to ``timestamp`` and return the predicted box."""
        dt = max(0.0, timestamp - self._time)
        self._time = max(self._time, timestamp)
        if dt > 0.0:
            size = _size(self.box)
            f = np.eye(6)
            f[0, 2] = f[1, 3] = dt
            q = np.zeros((6, 6))
            axis = white_noise_q(dt, (self.accel * size) ** 2)
            q[0:4:2, 0:4:2] = axis  # cx, vx
            q[1:4:2, 1:4:2] = axis  # cy, vy
            q[4, 4] = q[5, 5] = (self.size_rate * size) ** 2 * dt
            self._kf.predict(F=f, Q=q)
        return self.box

    def correct(self, box: Box, confidence: float = 1.0) -> Box:
        """Fold in a measured box; lower ``confidence`` means a weaker pull."""
        sigma = self.measurement * _size(box) / max(confidence, 1e-3)
        cx, cy = center(box)
        self._kf.update(np.array([cx, cy, box[2], box[3]], float), R=np.eye(4) * sigma**2)
        self._kf.x[4:6] = np.maximum(self._kf.x[4:6], 1.0)
        return self.box

    def stop(self) -> None:
        """Forget the velocity (the subject is lost; do not let the box drift away)."""
        self._kf.x[2:4] = 0.0

    @property
    def box(self) -> Box:
        cx, cy, _, _, w, h = self._kf.x
        return from_center(float(cx), float(cy), float(w), float(h))

    @property
    def velocity(self) -> tuple[float, float]:
        return (float(self._kf.x[2]), float(self._kf.x[3]))


def white_noise_q(dt: float, var: float) -> np.ndarray:
    """Process noise of one (position, velocity) axis over ``dt`` under white acceleration noise
    of variance ``var`` (the discrete model filterpy's ``Q_discrete_white_noise(dim=2)`` builds,
    written out: that helper costs several times more, and both filters call it every frame)."""
    dt2 = dt * dt
    return var * np.array([[0.25 * dt2 * dt2, 0.5 * dt2 * dt], [0.5 * dt2 * dt, dt2]])


def _size(box: Box) -> float:
    return float(np.sqrt(max(box[2], 1.0) * max(box[3], 1.0)))
