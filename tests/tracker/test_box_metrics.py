"""Hand-computed IoU, precision and success-AUC cases."""
import cv2
import pytest

from tracker.boxes import iou, polygon_to_box
from tracker.datasets import Sequence
from tracker.estimate import TargetEstimate, TrackState
from tracker.evaluation import PERTURBED_STARTS, perturbed_box, run_sequence
from tracker.metrics import SUCCESS_THRESHOLDS, precision_at, success_auc, success_curve
from tracker.synthetic import render_sequence


def test_iou_hand_cases():
    assert iou((0, 0, 10, 10), (0, 0, 10, 10)) == 1.0
    assert iou((0, 0, 10, 10), (5, 0, 10, 10)) == pytest.approx(50 / 150)
    assert iou((0, 0, 10, 10), (10, 0, 10, 10)) == 0.0
    assert iou((0, 0, 4, 4), (1, 1, 2, 2)) == pytest.approx(4 / 16)


def test_polygon_to_box_is_min_max():
    assert polygon_to_box([3, 1, 9, 2, 8, 7, 2, 6]) == (2, 1, 7, 6)


def test_thresholds_are_0_to_1_in_steps_of_005():
    assert len(SUCCESS_THRESHOLDS) == 21
    assert SUCCESS_THRESHOLDS[0] == 0.0 and SUCCESS_THRESHOLDS[-1] == 1.0


def test_success_auc_hand_case():
    truth = [(0, 0, 10, 10)] * 2
    # IoU 1 in one frame, 1/3 in the other: above thresholds 0..0.30 (7 values) for the
    # second frame, above 0..0.95 (20 values) for the first.
    predicted = [(0, 0, 10, 10), (5, 0, 10, 10)]
    curve = success_curve(predicted, truth)
    assert curve[0] == 1.0 and curve[-1] == 0.0
    assert success_auc(predicted, truth) == pytest.approx((20 + 7) / 2 / 21)


def test_precision_counts_centre_errors_up_to_the_limit():
    truth = [(0, 0, 10, 10)] * 4
    predicted = [(0, 0, 10, 10), (20, 0, 10, 10), (12, 16, 10, 10), (21, 0, 10, 10)]
    assert precision_at(predicted, truth) == pytest.approx(0.75)  # errors 0, 20, 20, 21


def test_mismatched_lengths_are_rejected():
    with pytest.raises(ValueError, match="equal"):
        success_auc([(0, 0, 1, 1)], [])


def test_perturbed_box_shifts_in_box_sizes_and_scales_about_the_centre():
    assert perturbed_box((10.0, 20.0, 40.0, 20.0), 0.1, -0.5, 1.0) == pytest.approx((14.0, 10.0, 40.0, 20.0))
    assert perturbed_box((10.0, 20.0, 40.0, 20.0), 0.0, 0.0, 0.5) == pytest.approx((20.0, 25.0, 20.0, 10.0))
    assert len(set(PERTURBED_STARTS)) == len(PERTURBED_STARTS) and (0.0, 0.0, 1.0) not in PERTURBED_STARTS


def test_run_sequence_starts_from_the_given_box(tmp_path):
    seq = render_sequence(frames=5, seed=0)
    paths = tuple(tmp_path / f"{i}.png" for i in range(5))
    for path, frame in zip(paths, seq.frames):
        cv2.imwrite(str(path), frame)
    start = perturbed_box(seq.boxes[0], 0.1, 0.0, 1.0)
    sequence = Sequence("synthetic", frame_paths=paths, groundtruth=tuple(seq.boxes))
    recorded = []

    class Recorder:
        def init(self, frame, box, timestamp):
            recorded.append(box)

        def update(self, frame, timestamp):
            return TargetEstimate(start, (0.0, 0.0), 1.0, TrackState.TRACKING, timestamp, 0)

    result = run_sequence(Recorder(), sequence, start=start)
    assert recorded == [start] and result.boxes[0] == start
