"""IoU of boxes that overlap along one axis only."""
import pytest

from tracker.runtime.boxes import iou


@pytest.mark.parametrize("other", [(2.0, 30.0, 10.0, 10.0), (30.0, 2.0, 10.0, 10.0), (-30.0, -2.0, 10.0, 10.0)])
def test_boxes_apart_on_one_axis_do_not_overlap(other: tuple[float, float, float, float]) -> None:
    """Side by side (or one above the other) with a shared span on the other axis: IoU is 0, not
    the negative ratio a negative intersection height or width times a positive one would give."""
    assert iou((0.0, 0.0, 10.0, 10.0), other) == 0.0
    assert iou(other, (0.0, 0.0, 10.0, 10.0)) == 0.0
