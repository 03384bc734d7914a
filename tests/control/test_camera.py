import math

import pytest
from hypothesis import given, strategies as st

from pipelines.control.camera import CameraModel, DEFAULT_HFOV_DEG


def test_default_hfov_is_24mm_on_full_frame():
    cam = CameraModel(1920, 1080)
    assert DEFAULT_HFOV_DEG == pytest.approx(73.74, abs=0.01)
    assert cam.hfov_deg == pytest.approx(73.74, abs=0.01)
    assert cam.focal_px == pytest.approx(960 / math.tan(math.radians(73.74 / 2)), rel=1e-3)


def test_focal_and_hfov_agree_and_are_exclusive():
    assert CameraModel(640, 360, focal_px=500).hfov_deg == pytest.approx(2 * math.degrees(math.atan(320 / 500)))
    assert CameraModel(640, 360, hfov_deg=60).focal_px == pytest.approx(320 / math.tan(math.radians(30)))
    with pytest.raises(ValueError):
        CameraModel(640, 360, hfov_deg=60, focal_px=500)
    with pytest.raises(ValueError):
        CameraModel(640, 360, hfov_deg=180)


def test_centre_is_on_axis_and_signs():
    cam = CameraModel(640, 360)
    assert cam.pixel_to_angles(320, 180) == (0.0, 0.0)
    yaw, pitch = cam.pixel_to_angles(600, 20)  # right and up
    assert yaw > 0 and pitch > 0


def test_off_axis_is_exact_not_small_angle():
    cam = CameraModel(640, 360, focal_px=320.0)
    # the right edge of the image is exactly 45 deg off axis (small angle would say 57.3 deg)
    assert cam.pixel_to_angles(640, 180) == pytest.approx((45.0, 0.0))
    # a corner pixel: pitch is measured after the yaw turn, over hypot(dx, f)
    yaw, pitch = cam.pixel_to_angles(640, 0)
    assert yaw == pytest.approx(45.0)
    assert pitch == pytest.approx(math.degrees(math.atan(180 / math.hypot(320, 320))))


@given(st.floats(-2000, 2000), st.floats(-2000, 2000), st.floats(20, 150))
def test_round_trip(x, y, hfov):
    cam = CameraModel(1280, 720, hfov_deg=hfov)
    yaw, pitch = cam.pixel_to_angles(x, y)
    bx, by = cam.angles_to_pixel(yaw, pitch)
    assert bx == pytest.approx(x, abs=1e-6) and by == pytest.approx(y, abs=1e-6)


def test_directions_behind_the_camera_are_rejected():
    with pytest.raises(ValueError):
        CameraModel(640, 360).angles_to_pixel(95.0, 0.0)


# Directions the pinhole model cannot map to a pixel.
@pytest.mark.parametrize("yaw, pitch", [(90.0, 0.0), (-95.0, 0.0), (0.0, 90.0), (0.0, -95.0), (10.0, -120.0)])
def test_directions_at_or_beyond_90_deg_on_either_axis_are_rejected(yaw: float, pitch: float) -> None:
    with pytest.raises(ValueError, match="not in front of the camera"):
        CameraModel(640, 360).angles_to_pixel(yaw, pitch)
