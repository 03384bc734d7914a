import cv2
import numpy as np
import pytest

from pipelines.control.metrics import MAX_ERROR
from pipelines.sources.virtual_camera import VirtualCamera


def _dot_frame(x, y):
    frame = np.zeros((720, 1280, 3), np.uint8)
    cv2.circle(frame, (x, y), 6, (255, 255, 255), -1)
    return frame


def _bright_centroid(image):
    ys, xs = np.nonzero(image[:, :, 0] > 128)
    return xs.mean(), ys.mean()


def test_crop_equivalent_view_at_rest_is_the_central_crop():
    vc = VirtualCamera((1280, 720))
    assert vc.camera.focal_px == pytest.approx(vc.source.focal_px)
    frame = np.random.default_rng(0).integers(0, 255, (720, 1280, 3), dtype=np.uint8)
    view = vc.render(frame, 0.0, 0.0)
    assert view.shape == (360, 640, 3)
    assert np.abs(view[5:-5, 5:-5].astype(int) - frame[185:535, 325:955].astype(int)).mean() < 1.0


@pytest.mark.parametrize("px", [(1000, 150), (200, 600), (640, 360)])
def test_turning_to_a_point_brings_it_to_the_view_centre(px):
    vc = VirtualCamera((1280, 720))
    yaw, pitch = vc.source.pixel_to_angles(*px)
    view = vc.render(_dot_frame(*px), yaw, pitch)
    assert _bright_centroid(view) == pytest.approx((319.5, 179.5), abs=0.6)
    err, inside = vc.center_error((px[0] - 5, px[1] - 5, 10, 10), yaw, pitch)
    assert inside and err == pytest.approx(0.0, abs=1e-9)


def test_boxes_map_where_the_render_puts_them():
    vc = VirtualCamera((1280, 720), hfov_deg=50.0)
    yaw, pitch = 12.0, -6.0
    view = vc.render(_dot_frame(900, 500), yaw, pitch)
    x, y, w, h = vc.box_to_view((894, 494, 12, 12), yaw, pitch)
    assert _bright_centroid(view) == pytest.approx((x + w / 2 - 0.5, y + h / 2 - 0.5), abs=0.7)


def test_centre_error_and_out_of_view():
    vc = VirtualCamera((1280, 720))
    err, inside = vc.center_error((1270, 710, 4, 4), 0.0, 0.0)  # source corner: outside the view
    assert not inside and err == pytest.approx(MAX_ERROR)  # capped
    err, inside = vc.center_error((640 + 320 - 1, 358, 0, 4), 0.0, 0.0)  # at the view's right edge
    assert inside and err == pytest.approx(319 / np.hypot(640, 360), abs=1e-3)
    assert vc.box_to_view((0, 0, 10, 10), 0.0, 0.0) is not None
    assert vc.box_to_view((0, 0, 10, 10), 180.0, 0.0) is None  # behind the view


@pytest.mark.parametrize("yaw, pitch, direction", [
    (80.0, 0.0, (-1.0, 0.0)),  # 80 deg to the left, in front: tan(80) f / diagonal would be 4.3
    (120.0, 0.0, (-1.0, 0.0)),  # behind, to the left (1.0 before)
    (0.0, -120.0, (0.0, -1.0)),  # behind, above
    (180.0, 0.0, None),  # straight behind: any direction
])
def test_error_is_capped_at_max_error_towards_the_subject(yaw, pitch, direction):
    """An out-of-view subject scores at most MAX_ERROR wherever it went, so mean and RMS stay
    comparable between runs that lose it."""
    vc = VirtualCamera((1280, 720))
    dx, dy, inside = vc.center_offset((636, 356, 8, 8), yaw, pitch)  # the source's centre
    assert not inside and np.hypot(dx, dy) == pytest.approx(MAX_ERROR)
    if direction is not None:
        assert (dx, dy) == pytest.approx(np.multiply(direction, MAX_ERROR), abs=1e-9)


def test_a_capped_offset_keeps_its_direction():
    vc = VirtualCamera((1280, 720), hfov_deg=30.0)
    dx, dy, inside = vc.center_offset((1270, 10, 4, 4), 0.0, 0.0)  # the source's top-right corner
    (x, y), = vc.to_view(np.array([[1272.0, 12.0]]), 0.0, 0.0)
    assert not inside and np.hypot(dx, dy) == pytest.approx(MAX_ERROR)
    assert np.arctan2(dy, dx) == pytest.approx(np.arctan2(y - vc.camera.cy, x - vc.camera.cx))


@pytest.mark.parametrize("box", [(np.nan,) * 4, (10.0, np.nan, 5.0, 5.0)])
def test_a_box_without_a_centre_is_refused(box):
    with pytest.raises(ValueError, match="no finite centre"):
        VirtualCamera((1280, 720)).center_offset(box, 0.0, 0.0)
