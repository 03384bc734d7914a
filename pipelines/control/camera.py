"""Pinhole camera model: pixels <-> angles off the optical axis (exact, no small-angle shortcut)."""
from __future__ import annotations

import math
import numbers

# A 24 mm lens on a full-frame (36 mm wide) sensor: hfov = 2 atan(18 / 24) ~ 73.74 deg.
DEFAULT_FOCAL_MM = 24.0
FULL_FRAME_WIDTH_MM = 36.0
DEFAULT_HFOV_DEG = math.degrees(2.0 * math.atan(FULL_FRAME_WIDTH_MM / 2.0 / DEFAULT_FOCAL_MM))


class CameraModel:
    """An ideal pinhole camera with square pixels and the principal point at the image centre.

    Angle conventions: yaw is positive to the right of the optical axis, pitch positive upwards.
    A pixel's (yaw, pitch) are the angles a yaw-then-pitch gimbal would turn to put that pixel
    on the optical axis: ``yaw = atan(dx / f)``, ``pitch = atan(-dy / hypot(dx, f))``.
    """

    def __init__(self, width: int, height: int, hfov_deg: float | None = None,
                 focal_px: float | None = None) -> None:
        if not all(isinstance(v, numbers.Integral) and not isinstance(v, bool) for v in (width, height)) \
                or width <= 0 or height <= 0:
            raise ValueError(f"image size must be positive whole pixels, got {width!r}x{height!r}")
        if hfov_deg is not None and focal_px is not None:
            raise ValueError("give hfov_deg or focal_px, not both")
        if focal_px is None:
            hfov = DEFAULT_HFOV_DEG if hfov_deg is None else hfov_deg
            if not 0.0 < hfov < 180.0:
                raise ValueError(f"hfov_deg must be in (0, 180), got {hfov}")
            focal_px = width / 2.0 / math.tan(math.radians(hfov) / 2.0)
        if not focal_px > 0 or not math.isfinite(focal_px):
            raise ValueError(f"focal_px must be positive and finite, got {focal_px}")
        self.width = int(width)
        self.height = int(height)
        self.focal_px = float(focal_px)
        self.cx = self.width / 2.0
        self.cy = self.height / 2.0

    @property
    def hfov_deg(self) -> float:
        return math.degrees(2.0 * math.atan(self.cx / self.focal_px))

    @property
    def diagonal_px(self) -> float:
        return math.hypot(self.width, self.height)

    def pixel_to_angles(self, x: float, y: float) -> tuple[float, float]:
        """(yaw, pitch) in degrees of the ray through pixel (x, y)."""
        dx, dy = x - self.cx, y - self.cy
        yaw = math.atan2(dx, self.focal_px)
        pitch = math.atan2(-dy, math.hypot(dx, self.focal_px))
        return math.degrees(yaw), math.degrees(pitch)

    def angles_to_pixel(self, yaw_deg: float, pitch_deg: float) -> tuple[float, float]:
        """The pixel whose ray has the given (yaw, pitch); |yaw| and |pitch| must be below 90."""
        if abs(yaw_deg) >= 90.0 or abs(pitch_deg) >= 90.0:
            raise ValueError(f"direction ({yaw_deg}, {pitch_deg}) is not in front of the camera")
        dx = self.focal_px * math.tan(math.radians(yaw_deg))
        dy = -math.hypot(dx, self.focal_px) * math.tan(math.radians(pitch_deg))
        return self.cx + dx, self.cy + dy

    def __repr__(self) -> str:
        return (f"CameraModel({self.width}x{self.height}, hfov={self.hfov_deg:.2f} deg, "
                f"focal={self.focal_px:.1f} px)")
