"""Speed and acceleration limits applied to every setpoint."""
from __future__ import annotations

import math

from pipelines.control.gimbal_link import PROTOCOL_MAX_SPEED_DPS
from pipelines.control.pid import clamp

__all__ = ["PROTOCOL_MAX_SPEED_DPS", "limit_rate"]


def limit_rate(previous: float, wanted: float, max_speed: float, max_accel: float, dt: float) -> float:
    """``wanted`` clamped to +-max_speed (and the protocol's 360 deg/s), moving at most
    ``max_accel * dt`` from ``previous``; the speed range wins when ``previous`` lies outside it.
    A NaN ``wanted`` is no setpoint at all: it counts as 0."""
    if math.isnan(wanted):
        wanted = 0.0
    speed = min(max_speed, PROTOCOL_MAX_SPEED_DPS)
    return clamp(previous + clamp(clamp(wanted, speed) - previous, max_accel * dt), speed)
