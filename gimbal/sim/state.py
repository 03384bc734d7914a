"""A thread-safe snapshot of the simulated gimbal, loggable as telemetry."""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any


@dataclass(frozen=True)
class SimState:
    """Angles in degrees (yaw, roll, pitch), speeds in °/s; counters since start."""

    time: float
    attitude: tuple[float, float, float]
    joint: tuple[float, float, float]
    speeds: tuple[float, float, float]
    axis_modes: tuple[str, str, str]
    moving: bool
    motors_on: bool
    speed_control: bool  # host holds speed control (ctrl_byte bit 7)
    limits: dict[str, int]  # user angle limits, whole degrees
    stiffness: dict[str, int]
    follow_mode: int
    orientation_deg: int
    selfie: bool
    activetrack: bool
    param_table: int
    roll360_mode: int
    push_enabled: bool
    calibration: tuple[int, int]  # state (0 idle, 1 running, 2 done, 3 error), progress %
    focus: dict[str, float | int]
    recording: bool
    photos: int
    external_versions: dict[int, int]  # from version pushes: device id -> version
    commands: dict[str, int]  # received, by message name
    sent: dict[str, int]  # replies and pushes sent, by message name
    faults: dict[str, int]  # faults injected and frames discarded, by kind

    def as_dict(self) -> dict[str, Any]:
        """JSON-friendly, for telemetry lines."""
        return {f.name: _plain(getattr(self, f.name)) for f in dataclasses.fields(self)}


def _plain(value: Any) -> Any:
    if isinstance(value, float):
        return round(value, 3)
    if isinstance(value, tuple | list):
        return [_plain(v) for v in value]
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    return value
