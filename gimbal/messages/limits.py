"""The document's value ranges and timing facts, in one place.

Ranges are in the wire's units (the messages check their fields against them); the figures in
degrees, °/s and seconds that callers need (the CLI's help, the keep-alive's clamp, control's
speed cap) are derived here, so no other module writes its own copy of a protocol limit.
"""
from __future__ import annotations

TENTHS = 10  # angles (°), speeds (°/s) and action times (s) travel in 0.1 units

# 2.3.4.1 position control, 0.1° (范围 -1800 ~ +1800, -300 ~ +300, -560 ~ +1460)
YAW_ANGLE_RANGE = (-1800, 1800)
ROLL_ANGLE_RANGE = (-300, 300)
PITCH_ANGLE_RANGE = (-560, 1460)
ANGLE_RANGES = {"yaw": YAW_ANGLE_RANGE, "roll": ROLL_ANGLE_RANGE, "pitch": PITCH_ANGLE_RANGE}
TIME_RANGE = (0, 0xFF)  # time_for_action, 0.1 s, a uint8_t: the document gives no narrower range

# 2.3.4.2 speed control, 0.1 °/s: the document gives 0..360 °/s as a magnitude; the sign is direction
SPEED_RANGE = (-3600, 3600)
MAX_SPEED_DPS = SPEED_RANGE[1] / TENTHS  # 360.0
SPEED_COMMAND_LASTS_S = 0.5  # 出于安全考虑，该指令每次只能控制 0.5s: resend to keep turning

# 2.3.4.4/2.3.4.5 user angle limits, whole degrees (min values are magnitudes below zero); 2.3.4.6/7
LIMIT_RANGES = {"pitch_max": (0, 145), "pitch_min": (0, 55), "yaw_max": (0, 179),
                "yaw_min": (0, 179), "roll_max": (0, 30), "roll_min": (0, 30)}
STIFFNESS_RANGES = {"pitch_stiffness": (0, 100), "roll_stiffness": (0, 100), "yaw_stiffness": (0, 100)}

# 2.3.4.11 external controllers, raw; 2.3.4.19 focus motor position
JOYSTICK_RANGE = (-15000, 15000)
DIAL_RANGE = (-2048, 2048)
FOCUS_POSITION_RANGE = (0, 4095)
