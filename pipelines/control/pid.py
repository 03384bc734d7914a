"""A discrete PID with the time step supplied by the caller."""
from __future__ import annotations

import math


def clamp(value: float, limit: float) -> float:
    """``value`` clamped into [-limit, limit]. NaN raises ``ValueError``: ``min``/``max`` would
    quietly turn it into +limit, a full-speed command from a number that means nothing."""
    if math.isnan(value):
        raise ValueError("cannot clamp NaN")
    return max(-limit, min(limit, value))


class Pid:
    """PID on ``error`` with anti-windup, output clamp, slew limit and a deadband.

    - ``deadband``: errors within +-deadband count as zero; outside it the deadband is subtracted,
      so the output stays continuous at its edge.
    - Integral: held as its contribution to the output, clamped to +-``integral_limit``, and not
      grown while the output is saturated in the direction of the error (conditional integration),
      at ``output_limit`` or at the ``bounds`` a call gives (what a limiter after the PID will let
      through this step, e.g. an acceleration limit: integrating what it holds back winds up);
      a call with ``integrate=False`` holds it (the caller knows the error is not a bias to remove).
    - Derivative: on the measurement when one is given (no kick on setpoint steps; the measurement
      is the controlled variable, error = setpoint - measurement), otherwise on the error.
      Zero on the first call.
    - Output: clamped to +-``output_limit``, then moved from the previous output by at most
      ``slew_rate * dt``.
    """

    def __init__(self, kp: float, ki: float = 0.0, kd: float = 0.0, *,
                 output_limit: float = math.inf, integral_limit: float = math.inf,
                 slew_rate: float = math.inf, deadband: float = 0.0) -> None:
        if min(output_limit, integral_limit, slew_rate) <= 0 or deadband < 0:
            raise ValueError("limits must be positive and the deadband non-negative")
        self.kp, self.ki, self.kd = kp, ki, kd
        self.output_limit = output_limit
        self.integral_limit = integral_limit
        self.slew_rate = slew_rate
        self.deadband = deadband
        self.reset()

    def reset(self, output: float = 0.0) -> None:
        """Forget the integral and derivative history; the slew limit restarts from ``output``."""
        self.integral = 0.0
        self.output = output
        self._last_error: float | None = None
        self._last_measurement: float | None = None

    def __call__(self, error: float, dt: float, measurement: float | None = None,
                 bounds: tuple[float, float] | None = None, integrate: bool = True) -> float:
        if not dt > 0.0:
            raise ValueError(f"dt must be positive, got {dt}")
        e = math.copysign(max(abs(error) - self.deadband, 0.0), error)

        if measurement is not None:
            rate = 0.0 if self._last_measurement is None else -(measurement - self._last_measurement) / dt
            self._last_measurement = measurement
        else:
            rate = 0.0 if self._last_error is None else (e - self._last_error) / dt
        self._last_error = e

        p, d = self.kp * e, self.kd * rate
        integral = clamp(self.integral + self.ki * e * dt, self.integral_limit) if integrate else self.integral
        raw = p + integral + d
        limited = self._limit(raw, bounds)
        if limited != raw and e * (raw - limited) > 0.0 and abs(integral) > abs(self.integral):
            integral = self.integral  # saturated: do not wind further in the error's direction
            limited = self._limit(p + integral + d, bounds)
        self.integral = integral

        step = self.slew_rate * dt
        self.output = self.output + clamp(limited - self.output, step)
        return self.output

    def _limit(self, value: float, bounds: tuple[float, float] | None) -> float:
        value = clamp(value, self.output_limit)
        return value if bounds is None else min(max(value, bounds[0]), bounds[1])
