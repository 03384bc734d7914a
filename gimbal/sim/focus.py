"""The focus motor (0x0E/0x12): position control, calibration state machine and read-out."""
from __future__ import annotations

from gimbal.messages.external import (FOCUS_CAL_AUTO, FOCUS_CAL_MANUAL, FOCUS_CAL_NONE,
                                      FOCUS_CAL_SET_MAX, FOCUS_CAL_SET_MIN, FOCUS_CAL_STOP,
                                      FOCUS_CALIBRATED, FOCUS_CALIBRATING, FOCUS_NOT_CALIBRATED,
                                      FOCUS_POSITION_RANGE)


class FocusMotor:
    """Moves toward its target at ``speed`` units/s within the travel (0..4095, or the calibrated
    span); a dial speed drives it for 0.5 s per push."""

    def __init__(self, speed: float, calibration_s: float) -> None:
        self.speed = speed
        self.calibration_s = calibration_s
        self.position = 0.0
        self.target = 0.0
        self.state = FOCUS_NOT_CALIBRATED
        self.travel = (float(FOCUS_POSITION_RANGE[0]), float(FOCUS_POSITION_RANGE[1]))
        self.marks: dict[str, float] = {}  # manual calibration points
        self._calibration_done_at = 0.0
        self._dial = 0.0
        self._dial_until = 0.0
        self._last: float | None = None

    def move_to(self, position: int) -> None:
        self._dial = 0.0
        self.target = self._clamp(float(position))

    def dial(self, fraction: float, now: float, hold_for: float) -> None:
        """Drive at ``fraction`` (-1..1) of full speed for ``hold_for`` s."""
        self._dial = fraction * self.speed
        self._dial_until = now + hold_for

    def calibrate(self, command: int, now: float) -> bool:
        """Run one calibration command; False when it cannot be carried out."""
        if command == FOCUS_CAL_NONE:
            return True
        if command == FOCUS_CAL_AUTO:
            self.state = FOCUS_CALIBRATING
            self._calibration_done_at = now + self.calibration_s
            return True
        if command in (FOCUS_CAL_SET_MIN, FOCUS_CAL_SET_MAX):
            self.marks["min" if command == FOCUS_CAL_SET_MIN else "max"] = self.position
            return True
        if command == FOCUS_CAL_MANUAL:
            low, high = self.marks.get("min"), self.marks.get("max")
            if low is None or high is None or low >= high:
                return False
            self.travel, self.state = (low, high), FOCUS_CALIBRATED
            self.target = self._clamp(self.target)
            return True
        if command == FOCUS_CAL_STOP:
            if self.state != FOCUS_CALIBRATING:
                return False
            self.state = FOCUS_NOT_CALIBRATED
            return True
        return False

    def advance(self, now: float) -> None:
        """Integrate from the previous call to ``now`` (split exactly where a dial push expires)."""
        if self._dial and self._last is not None and self._last < self._dial_until < now:
            self.advance(self._dial_until)
        dt = 0.0 if self._last is None else max(0.0, now - self._last)
        self._last = now
        if self.state == FOCUS_CALIBRATING and now >= self._calibration_done_at:
            self.state = FOCUS_CALIBRATED
            self.travel = (float(FOCUS_POSITION_RANGE[0]), float(FOCUS_POSITION_RANGE[1]))
        if self._dial and now <= self._dial_until:
            self.target = self._clamp(self.position + self._dial * dt)
        step = self.speed * dt
        self.position += max(-step, min(step, self.target - self.position))

    def _clamp(self, position: float) -> float:
        return max(self.travel[0], min(self.travel[1], position))
