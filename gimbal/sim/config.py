"""The simulated gimbal's configuration: ids, firmware layout, rates and the axis model."""
from __future__ import annotations

from dataclasses import dataclass

from gimbal.messages.telemetry import DEVICE_ID_R_SDK
from gimbal.transport import HOST_RX_ID, HOST_TX_ID


@dataclass(frozen=True)
class SimConfig:
    """Every knob of the simulated device; the defaults behave like an RS 2 / RS 3 Pro."""

    rx_id: int = HOST_TX_ID  # the device listens where the host sends (0x223)
    tx_id: int = HOST_RX_ID  # and answers where the host listens (0x222)
    legacy: bool = False  # old firmware: replies omit CmdSet/CmdID
    push_rate_hz: float = 50.0  # parameter push (0x08) rate once enabled
    tick_hz: float = 200.0  # the grain of injected foreign traffic (everything else is sent when due)
    max_speed_dps: float = 360.0
    accel_dps2: float = 720.0  # speed changes (speed control, joystick, stops) are rate-limited
    speed_timeout_s: float = 0.5  # the document's 0.5 s rule
    base_yaw_deg: float = 0.0  # attitude yaw = joint yaw + this (the handle's heading)
    yaw_continuous: bool = False  # True: yaw wraps at ±180° and ignores the yaw limits
    recenter_speed_dps: float = 100.0  # recenter and selfie moves
    joystick_full_scale_dps: float = 150.0  # joystick ±15000 -> ± this
    speed_signs: tuple[int, int, int] = (1, 1, 1)  # yaw, roll, pitch: -1 flips an axis
    initial_joint_deg: tuple[float, float, float] = (0.0, 0.0, 0.0)  # yaw, roll, pitch
    device_id: int = DEVICE_ID_R_SDK  # the module answered by the version query (0x09)
    version: int = 0x02050000  # 0xAABBCCDD = AA.BB.CC.DD
    calibration_s: float = 3.0  # auto-calibration (0x0F) duration
    calibration_push_hz: float = 10.0  # its status pushes (0x10)
    focus_speed: float = 4095.0  # focus motor units per second
    focus_calibration_s: float = 1.0  # focus motor auto-calibration duration
    camera_connected: bool = True  # False: camera commands fail with 0x02

    def __post_init__(self) -> None:
        for name in ("push_rate_hz", "tick_hz", "max_speed_dps", "accel_dps2", "speed_timeout_s",
                     "recenter_speed_dps", "joystick_full_scale_dps", "calibration_push_hz",
                     "focus_speed"):
            if not getattr(self, name) > 0:
                raise ValueError(f"SimConfig.{name} must be positive, not {getattr(self, name)}")
        if any(s not in (-1, 1) for s in self.speed_signs) or len(self.speed_signs) != 3:
            raise ValueError(f"SimConfig.speed_signs must be three of ±1, not {self.speed_signs}")
        if not 0 <= self.version <= 0xFFFFFFFF:
            raise ValueError(f"SimConfig.version 0x{self.version:X} does not fit 32 bits")
