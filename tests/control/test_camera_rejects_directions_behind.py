"""Directions the pinhole model cannot map to a pixel."""
import pytest

from pipelines.control.camera import CameraModel


@pytest.mark.parametrize("yaw, pitch", [(90.0, 0.0), (-95.0, 0.0), (0.0, 90.0), (0.0, -95.0), (10.0, -120.0)])
def test_directions_at_or_beyond_90_deg_on_either_axis_are_rejected(yaw: float, pitch: float) -> None:
    with pytest.raises(ValueError, match="not in front of the camera"):
        CameraModel(640, 360).angles_to_pixel(yaw, pitch)
