"""One gimbal axis: uniform position moves, rate-limited speed control and hard stops at limits."""
from __future__ import annotations

import math
from dataclasses import dataclass
from enum import Enum


class AxisMode(str, Enum):
    HOLD = "hold"  # no command: decelerate to rest and stay
    MOVE = "move"  # position control: uniform motion to a target
    SPEED = "speed"  # speed control / joystick: track a speed until it expires


@dataclass(frozen=True)
class AxisRange:
    """Allowed joint angles in degrees; ``wraps`` makes the axis continuous over ±180°."""

    low: float
    high: float
    wraps: bool = False

    def contains(self, angle: float) -> bool:
        return self.wraps or self.low - 1e-9 <= angle <= self.high + 1e-9


def wrap180(angle: float) -> float:
    """An angle in [-180, 180)."""
    return (angle + 180.0) % 360.0 - 180.0


class Axis:
    """Angle (°) and velocity (°/s) of one motor, advanced by ``advance(now, allowed)``."""

    def __init__(self, angle: float, max_speed: float, accel: float) -> None:
        self.angle = angle
        self.velocity = 0.0
        self.max_speed = max_speed
        self.accel = accel
        self.mode = AxisMode.HOLD
        self._move: tuple[float, float, float, float] | None = None  # start, target, t0, duration
        self._speed = 0.0
        self._speed_until = 0.0
        self._last: float | None = None

    def move_to(self, target: float, duration: float, now: float) -> None:
        """Uniform motion from the current angle to ``target`` in ``duration`` s."""
        self.mode = AxisMode.MOVE
        self._move = (self.angle, target, now, duration)
        self.velocity = 0.0 if duration <= 0 else (target - self.angle) / duration

    def set_speed(self, speed: float, now: float, hold_for: float) -> None:
        """Track ``speed`` (clamped to the maximum) until ``now + hold_for``; 0 stops."""
        self.mode = AxisMode.SPEED
        self._move = None
        self._speed = max(-self.max_speed, min(self.max_speed, speed))
        self._speed_until = now + hold_for if speed else now

    def stop(self) -> None:
        """Decelerate to rest (ends speed control and position moves)."""
        self.mode = AxisMode.HOLD
        self._move = None

    def halt(self) -> None:
        """Stop dead (motors switched off)."""
        self.stop()
        self.velocity = 0.0

    def advance(self, now: float, allowed: AxisRange) -> None:
        """Integrate from the previous call to ``now`` (split exactly where a speed expires)."""
        if self.mode is AxisMode.SPEED and self._last is not None and self._last < self._speed_until < now:
            self.advance(self._speed_until, allowed)
        commanded = self._last is not None and self._last < self._speed_until
        dt = 0.0 if self._last is None else max(0.0, now - self._last)
        self._last = now
        if self.mode is AxisMode.MOVE and self._move is not None:
            start, target, t0, duration = self._move
            done = duration <= 0 or now >= t0 + duration
            self.angle = target if done else start + (target - start) * (now - t0) / duration
            if done:
                self.velocity = 0.0
                self.mode = AxisMode.HOLD
                self._move = None
        else:
            wanted = self._speed if self.mode is AxisMode.SPEED and commanded else 0.0
            before = self.velocity
            ramp = min(dt, abs(wanted - before) / self.accel)  # exact: ramp, then constant speed
            self.velocity = wanted if ramp < dt else before + math.copysign(self.accel * ramp, wanted - before)
            self.angle += 0.5 * (before + self.velocity) * ramp + self.velocity * (dt - ramp)
            if abs(self.velocity) < 1e-9:
                self.velocity = 0.0
            if self.mode is AxisMode.SPEED and now >= self._speed_until and self.velocity == 0.0:
                self.mode = AxisMode.HOLD
        self._apply_range(allowed)

    def _apply_range(self, allowed: AxisRange) -> None:
        if allowed.wraps:
            self.angle = wrap180(self.angle)
            return
        if allowed.low <= self.angle <= allowed.high:
            return
        if self.mode is AxisMode.MOVE and self._move is not None and allowed.contains(self._move[1]):
            return  # a move into the range (the pull-back after new limits) brings the axis there
        self.angle = min(allowed.high, max(allowed.low, self.angle))
        self.velocity = 0.0
        if self.mode is AxisMode.MOVE:
            self.mode, self._move = AxisMode.HOLD, None
