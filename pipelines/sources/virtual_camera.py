"""A narrow virtual camera on a simulated gimbal, looking into a wide recorded frame.

The recorded frame is treated as a fixed wide pinhole camera pointing at yaw = pitch = 0; the
virtual camera sits at the same centre, turned to the gimbal's (yaw, pitch), and sees the part of
the frame its rotation homography ``K_view R^T K_source^-1`` selects. Ground-truth boxes of the
recorded frame map into the view the same way, so the centring error is known every frame.
"""
from __future__ import annotations

import math

import cv2
import numpy as np

from pipelines.control.camera import CameraModel
from pipelines.control.direction import rotation_matrix
from pipelines.control.metrics import MAX_ERROR
from tracker.runtime.boxes import Box, center

# (forward, right, up) -> OpenCV camera axes (x right, y down, z forward)
_TO_CV = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, -1.0], [1.0, 0.0, 0.0]])


def _intrinsics(cam: CameraModel) -> np.ndarray:
    return np.array([[cam.focal_px, 0.0, cam.cx], [0.0, cam.focal_px, cam.cy], [0.0, 0.0, 1.0]])


def _capped(dx: float, dy: float, behind: bool) -> tuple[float, float]:
    """The offset shortened to at most ``MAX_ERROR``; ``behind``: stretched to it (an offset of
    infinite length in that direction; straight behind counts as right)."""
    length = math.hypot(dx, dy)
    if length == 0.0:
        return (MAX_ERROR, 0.0) if behind else (0.0, 0.0)
    scale = MAX_ERROR / length if behind else min(1.0, MAX_ERROR / length)
    return dx * scale, dy * scale


class VirtualCamera:
    """The view of an ``out_size`` camera on a gimbal inside a ``source_size`` recorded frame.

    ``hfov_deg`` is the view's horizontal field of view; ``None`` means crop-equivalent (the
    source's focal length, so a 640x360 view of a 1280x720 frame is its central half at rest).
    ``source_hfov_deg`` is the recorded camera's field of view (default: 24 mm full frame).
    """

    def __init__(self, source_size: tuple[int, int], out_size: tuple[int, int] = (640, 360),
                 hfov_deg: float | None = None, source_hfov_deg: float | None = None) -> None:
        self.source = CameraModel(*source_size, hfov_deg=source_hfov_deg)
        if hfov_deg is None:
            self.camera = CameraModel(*out_size, focal_px=self.source.focal_px)
        else:
            self.camera = CameraModel(*out_size, hfov_deg=hfov_deg)
        self._k_src = _intrinsics(self.source)
        self._k_view_inv = np.linalg.inv(_intrinsics(self.camera))
        self._last: tuple[tuple[float, float], np.ndarray, np.ndarray] | None = None

    def _homographies(self, yaw: float, pitch: float) -> tuple[np.ndarray, np.ndarray]:
        """Homographies view -> source and source -> view for a gimbal at (yaw, pitch) degrees.

        The last attitude's pair is kept, so rendering a frame and mapping its boxes at the same
        attitude builds them once.
        """
        last = self._last
        if last is None or last[0] != (yaw, pitch):
            r_cv = _TO_CV @ rotation_matrix(yaw, pitch) @ _TO_CV.T
            to_source = self._k_src @ r_cv @ self._k_view_inv
            last = self._last = ((yaw, pitch), to_source, np.linalg.inv(to_source))
        return last[1], last[2]

    def render(self, frame: np.ndarray, yaw: float, pitch: float) -> np.ndarray:
        """What the view sees (black where it looks past the recorded frame)."""
        h, _ = self._homographies(yaw, pitch)
        return cv2.warpPerspective(frame, h, (self.camera.width, self.camera.height),
                                   flags=cv2.INTER_LINEAR | cv2.WARP_INVERSE_MAP,
                                   borderMode=cv2.BORDER_CONSTANT)

    def _homogeneous(self, points: np.ndarray, yaw: float, pitch: float) -> np.ndarray:
        """Source pixels (N x 2) -> homogeneous view pixels (N x 3), the third value above 0 in
        front of the view: ``K_view`` times the view ray of each point."""
        _, h = self._homographies(yaw, pitch)
        return np.c_[np.asarray(points, float).reshape(-1, 2), np.ones(len(points))] @ h.T

    def to_view(self, points: np.ndarray, yaw: float, pitch: float) -> np.ndarray:
        """Source pixels (N x 2) -> view pixels (N x 2); NaN for points behind the view."""
        p = self._homogeneous(points, yaw, pitch)
        out = p[:, :2] / p[:, 2:3]
        out[p[:, 2] <= 0] = np.nan
        return out

    def box_to_view(self, box: Box, yaw: float, pitch: float) -> Box | None:
        """The axis-aligned view box around a source box's mapped corners (``None`` if behind)."""
        x, y, w, h = box
        corners = self.to_view(np.array([[x, y], [x + w, y], [x, y + h], [x + w, y + h]]), yaw, pitch)
        if np.isnan(corners).any():
            return None
        (x0, y0), (x1, y1) = corners.min(axis=0), corners.max(axis=0)
        return (float(x0), float(y0), float(x1 - x0), float(y1 - y0))

    def center_offset(self, box: Box, yaw: float, pitch: float) -> tuple[float, float, bool]:
        """Signed offset (dx, dy) of the box centre from the view centre as fractions of the view
        diagonal (right, down positive), and whether the centre lies inside the view.

        The offset is at most ``MAX_ERROR`` long: a centre further out keeps its direction, and one
        behind the view is ``MAX_ERROR`` towards it. A box without a finite centre is a ValueError.
        """
        point = np.array([center(box)], float)
        if not np.isfinite(point).all():
            raise ValueError(f"box {box} has no finite centre")
        (x, y, z), = self._homogeneous(point, yaw, pitch).tolist()
        cam = self.camera
        if z <= 0:
            return *_capped(x - cam.cx * z, y - cam.cy * z, behind=True), False
        cx, cy = x / z, y / z
        inside = 0.0 <= cx < cam.width and 0.0 <= cy < cam.height
        dx, dy = _capped((cx - cam.cx) / cam.diagonal_px, (cy - cam.cy) / cam.diagonal_px, behind=False)
        return dx, dy, inside

    def center_error(self, box: Box, yaw: float, pitch: float) -> tuple[float, bool]:
        """Distance from the box centre to the view centre as a fraction of the view diagonal,
        and whether the centre lies inside the view."""
        dx, dy, inside = self.center_offset(box, yaw, pitch)
        return float(np.hypot(dx, dy)), inside
