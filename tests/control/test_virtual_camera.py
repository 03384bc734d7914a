import cv2
import numpy as np
import pytest

from pipelines.virtual_camera import VirtualCamera


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
    assert not inside and err > 0.5
    err, inside = vc.center_error((640 + 320 - 1, 358, 0, 4), 0.0, 0.0)  # at the view's right edge
    assert inside and err == pytest.approx(319 / np.hypot(640, 360), abs=1e-3)
    assert vc.box_to_view((0, 0, 10, 10), 0.0, 0.0) is not None
    assert vc.box_to_view((0, 0, 10, 10), 180.0, 0.0) is None  # behind the view
