"""The simulated gimbal's configuration: ids, firmware layout, rates and the axis model."""
from __future__ import annotations

from dataclasses import dataclass

from gimbal.messages.firmware import LEGACY_ORDER_DOCUMENT, LEGACY_ORDERS
from gimbal.messages.telemetry import DEVICE_ID_R_SDK, DEVICE_ID_RANGE
from gimbal.sim.checks import FieldError, check
from gimbal.transport import HOST_RX_ID, HOST_TX_ID
from gimbal.values import integer, is_flag, number


@dataclass(frozen=True)
class SimConfig:
    """Every knob of the simulated device; the defaults behave like an RS 2 / RS 3 Pro."""

    rx_id: int = HOST_TX_ID  # the device listens where the host sends (0x223)
    tx_id: int = HOST_RX_ID  # and answers where the host listens (0x222)
    legacy: bool = False  # old firmware: replies omit CmdSet/CmdID
    legacy_attitude_order: str = LEGACY_ORDER_DOCUMENT  # axis order of legacy angle replies ("ypr": ArduPilot's)
    push_reply_bit: bool = False  # pushes (0x08, 0x10) with CmdType 0x20, as some firmware sends them
    lenient: bool = False  # answer get requests that come without their payload (limits, stiffness, user params)
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
        check(self, RULES)
        if self.tx_id == self.rx_id:
            raise FieldError("SimConfig", "tx_id", f"an id other than rx_id (0x{self.rx_id:03X})", self.tx_id)


#: Pushes a second at most. The document gives no rate for the parameter push (it gives 1 Hz for the
#: version push, 100 Hz for the focus position push; public drivers see ~50 Hz); the bus bounds it:
#: a 40-byte push is 5 CAN frames, so 1,000 a second are 5,000 frames, over half of the ~8,000-9,000
#: a 1 Mbit/s classic CAN bus carries, and ~1,700 would leave no room for the host's commands.
MAX_PUSH_RATE_HZ = 1000.0

_RATE, _SPEED, _TIME = "a finite rate above 0 Hz", "a finite speed above 0 °/s", "a finite time, 0 s or more"
_PUSH_RATE = (f"a rate above 0 Hz, at most {MAX_PUSH_RATE_HZ:g} Hz (a push takes several frames of a 1 Mbit/s bus)",
              number(0, MAX_PUSH_RATE_HZ, above=True))
_CAN_ID = ("a standard CAN id, 0 to 0x7FF", integer(0, 0x7FF))
_FLAG = "True or False"
#: field: (what it takes, test); NaN and infinities fail every test.
RULES = {
    "rx_id": _CAN_ID, "tx_id": _CAN_ID,
    "legacy": (_FLAG, is_flag), "yaw_continuous": (_FLAG, is_flag), "camera_connected": (_FLAG, is_flag),
    "push_reply_bit": (_FLAG, is_flag), "lenient": (_FLAG, is_flag),
    "legacy_attitude_order": (f"one of {', '.join(LEGACY_ORDERS)}", lambda v: v in LEGACY_ORDERS),
    "push_rate_hz": _PUSH_RATE,
    "tick_hz": (_RATE, number(0, above=True)),
    "max_speed_dps": (_SPEED, number(0, above=True)),
    "accel_dps2": ("a finite acceleration above 0", number(0, above=True)),
    "speed_timeout_s": ("a finite time above 0 s", number(0, above=True)),
    "base_yaw_deg": ("a finite angle", number()),
    "recenter_speed_dps": (_SPEED, number(0, above=True)),
    "joystick_full_scale_dps": (_SPEED, number(0, above=True)),
    "speed_signs": ("three of ±1", lambda v: isinstance(v, tuple) and len(v) == 3 and all(s in (-1, 1) for s in v)),
    "initial_joint_deg": ("three finite angles", lambda v: isinstance(v, tuple) and len(v) == 3
                          and all(map(number(), v))),
    "device_id": ("a device id, 1 to 0xFFFFFFFF (0 is reserved)", integer(*DEVICE_ID_RANGE)),
    "version": ("a 32-bit version, 0 to 0xFFFFFFFF", integer(0, 0xFFFFFFFF)),
    "calibration_s": (_TIME, number(0)),
    "calibration_push_hz": _PUSH_RATE,
    "focus_speed": ("a finite speed above 0 units/s", number(0, above=True)),
    "focus_calibration_s": (_TIME, number(0)),
}
