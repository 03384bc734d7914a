"""World-frame target direction: composing image offsets with the gimbal attitude, and its Kalman filter.

Angles are degrees; yaw positive to the right (clockwise seen from above), pitch positive up.
The gimbal is modelled as yaw-then-pitch (roll held level), so a target's world direction is
``Rz(gimbal_yaw) @ Ry(gimbal_pitch) @ ray(offset_yaw, offset_pitch)``.
"""
from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass, replace

from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from filterpy.kalman import KalmanFilter


def wrap_deg(angle: float) -> float:
    """``angle`` wrapped into [-180, 180)."""
    return (angle + 180.0) % 360.0 - 180.0


def _unit(yaw_deg: float, pitch_deg: float) -> np.ndarray:
    y, p = math.radians(yaw_deg), math.radians(pitch_deg)
    return np.array([math.cos(p) * math.cos(y), math.cos(p) * math.sin(y), math.sin(p)])


def _angles(v: np.ndarray) -> tuple[float, float]:
    yaw = math.degrees(math.atan2(v[1], v[0]))
    pitch = math.degrees(math.asin(max(-1.0, min(1.0, float(v[2])))))
    return wrap_deg(yaw), pitch


def rotation_matrix(yaw_deg: float, pitch_deg: float) -> np.ndarray:
    """Camera frame (forward, right, up) -> world frame for a gimbal at (yaw, pitch)."""
    cy, sy = math.cos(math.radians(yaw_deg)), math.sin(math.radians(yaw_deg))
    cp, sp = math.cos(math.radians(pitch_deg)), math.sin(math.radians(pitch_deg))
    rz = np.array([[cy, -sy, 0.0], [sy, cy, 0.0], [0.0, 0.0, 1.0]])
    ry = np.array([[cp, 0.0, -sp], [0.0, 1.0, 0.0], [sp, 0.0, cp]])
    return rz @ ry


def compose(gimbal: tuple[float, float], offset: tuple[float, float]) -> tuple[float, float]:
    """World (yaw, pitch) of a ray at ``offset`` (yaw, pitch) off the axis of a gimbal at ``gimbal``."""
    return _angles(rotation_matrix(*gimbal) @ _unit(*offset))


def relative(gimbal: tuple[float, float], world: tuple[float, float]) -> tuple[float, float]:
    """Inverse of :func:`compose`: the offset (yaw, pitch) of world direction ``world`` in the view."""
    return _angles(rotation_matrix(*gimbal).T @ _unit(*world))


@dataclass(frozen=True, slots=True)
class Direction:
    """Filtered world direction (deg) and angular velocity (deg/s) at ``timestamp``."""

    yaw: float
    pitch: float
    yaw_rate: float
    pitch_rate: float
    timestamp: float

    def at(self, t: float) -> tuple[float, float]:
        """Constant-velocity extrapolation to time ``t`` (yaw wrapped)."""
        dt = t - self.timestamp
        return wrap_deg(self.yaw + self.yaw_rate * dt), self.pitch + self.pitch_rate * dt

    def shifted(self, dyaw: float, dpitch: float) -> Direction:
        """The same direction moved by (``dyaw``, ``dpitch``) degrees."""
        return replace(self, yaw=wrap_deg(self.yaw + dyaw), pitch=self.pitch + dpitch)


class DirectionFilter:
    """Constant-velocity Kalman filter on (yaw, pitch); state ``[yaw, yaw', pitch, pitch']``.

    Yaw is kept unwrapped inside the filter (measurements are unwrapped next to the prediction),
    so crossing +-180 deg does not produce a 360 deg jump.
    """

    def __init__(self, measurement_std_deg: float = 0.15, accel_std_dps2: float = 300.0,
                 initial_rate_std_dps: float = 60.0) -> None:
        self.measurement_std_deg = measurement_std_deg
        self.accel_std_dps2 = accel_std_dps2
        self.initial_rate_std_dps = initial_rate_std_dps
        self._kf: KalmanFilter | None = None
        self._t = 0.0

    def reset(self) -> None:
        self._kf = None

    def shift(self, dyaw: float, dpitch: float) -> None:
        """Move the filtered direction by (``dyaw``, ``dpitch``): the frame it was measured in moved."""
        if self._kf is not None:
            self._kf.x[0] += dyaw
            self._kf.x[2] += dpitch

    def _start(self, z: tuple[float, float], t: float) -> None:
        from filterpy.kalman import KalmanFilter  # noqa: PLC0415 (filterpy loads SciPy: only a run needs it)
        kf = KalmanFilter(dim_x=4, dim_z=2)
        kf.x = np.array([z[0], 0.0, z[1], 0.0])
        kf.H = np.array([[1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0]])
        kf.R = np.eye(2) * self.measurement_std_deg ** 2
        pos_var, rate_var = self.measurement_std_deg ** 2, self.initial_rate_std_dps ** 2
        kf.P = np.diag([pos_var, rate_var, pos_var, rate_var])
        self._kf, self._t = kf, t

    def _predict(self, t: float) -> None:
        kf = self._kf
        dt = t - self._t
        if dt <= 0.0:
            return
        kf.F = np.array([[1.0, dt, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0],
                         [0.0, 0.0, 1.0, dt], [0.0, 0.0, 0.0, 1.0]])
        from filterpy.common import Q_discrete_white_noise  # noqa: PLC0415 (loaded by _start already)
        kf.Q = Q_discrete_white_noise(dim=2, dt=dt, var=self.accel_std_dps2 ** 2, block_size=2)  # yaw, pitch
        kf.predict()
        self._t = t

    def update(self, measurement: tuple[float, float] | None, timestamp: float) -> Direction | None:
        """Fold in a (yaw, pitch) measurement at ``timestamp``; ``None`` only predicts.

        Returns the state at ``timestamp`` (``None`` before the first measurement).
        """
        if self._kf is None:
            if measurement is None:
                return None
            self._start(measurement, timestamp)
        else:
            self._predict(timestamp)
            if measurement is not None:
                yaw = self._kf.x[0] + wrap_deg(measurement[0] - self._kf.x[0])
                self._kf.update(np.array([yaw, measurement[1]]))
        x = self._kf.x
        return Direction(wrap_deg(float(x[0])), float(x[2]), float(x[1]), float(x[3]), self._t)


class PredictionTrust:
    """How much of the filter's extrapolation to use at the loop's own prediction horizon.

    Every new measurement is compared with the filter as it stood ``horizon`` earlier: its
    extrapolation predicted a displacement ``d`` (from its then direction), the target actually
    moved ``m``. The trust is the least-squares gain of ``m`` on ``d`` over an exponential memory
    of ``memory_s``, ``weight = E[m.d] / E[d.d]`` clipped to [0, 1]: the share of the predicted
    motion that has been happening. Near 1 for smooth motion (pans, ramps, sines, ballistic
    arcs), near 0 when contacts and reversals make the extrapolation no better than standing
    still. It starts trusting (prior gain 1 worth ``prior_deg2``).
    """

    def __init__(self, memory_s: float = 1.0, prior_deg2: float = 0.01) -> None:
        self.memory_s = memory_s
        self.prior_deg2 = prior_deg2
        self._history: deque[Direction] = deque(maxlen=64)
        self.reset()

    @property
    def weight(self) -> float:
        return min(1.0, max(0.0, self._cross / self._predicted))

    def reset(self) -> None:
        self._cross = self._predicted = self.prior_deg2
        self._history.clear()
        self._last_t: float | None = None

    def observe(self, measurement: tuple[float, float], t: float, horizon: float) -> None:
        """Score the prediction made ``horizon`` before ``t`` against ``measurement``."""
        past = next((d for d in reversed(self._history) if d.timestamp <= t - horizon + 1e-6), None)
        if past is None:
            return
        yaw, pitch = past.at(t)
        predicted = (wrap_deg(yaw - past.yaw), pitch - past.pitch)
        moved = (wrap_deg(measurement[0] - past.yaw), measurement[1] - past.pitch)
        keep = math.exp(-max(t - (past.timestamp if self._last_t is None else self._last_t), 0.0)
                        / self.memory_s)
        self._cross = keep * self._cross + (1.0 - keep) * (moved[0] * predicted[0] + moved[1] * predicted[1])
        self._predicted = keep * self._predicted + (1.0 - keep) * (predicted[0] ** 2 + predicted[1] ** 2)
        self._last_t = t

    def add(self, direction: Direction) -> None:
        self._history.append(direction)

    def shift(self, dyaw: float, dpitch: float) -> None:
        """Move the remembered directions by (``dyaw``, ``dpitch``), as :meth:`DirectionFilter.shift`."""
        self._history = deque((d.shifted(dyaw, dpitch) for d in self._history), maxlen=self._history.maxlen)
