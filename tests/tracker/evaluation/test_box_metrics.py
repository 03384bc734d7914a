"""Hand-computed IoU, precision and success-AUC cases."""
from __future__ import annotations

import json
import math
from collections.abc import Callable

import cv2
import numpy as np
import pytest

from tracker.evaluation import PERTURBED_STARTS, SequenceResult, perturbed_box, run_sequence, summarize
from tracker.evaluation.datasets import Sequence
from tracker.evaluation.metrics import (
    SUCCESS_THRESHOLDS, center_errors, has_truth, overlaps, precision_at, success_auc, success_curve,
)
from tracker.evaluation.synthetic import render_sequence
from tracker.runtime.boxes import iou, polygon_to_box
from tracker.runtime.estimate import TargetEstimate, TrackState


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


NAN_BOX = (math.nan,) * 4


def test_a_box_without_width_height_or_finite_values_is_no_ground_truth():
    assert has_truth((0, 0, 10, 10)) and has_truth((-5, -5, 0.5, 1))
    for box in (NAN_BOX, (0, 0, 0, 0), (3, 4, 0, 10), (3, 4, 10, -1), (math.inf, 0, 10, 10)):
        assert not has_truth(box)


def test_frames_without_ground_truth_are_left_out_of_both_scores():
    """NaN and 0,0,0,0 boxes (subject not visible) count neither as misses nor as hits (pytracking's
    OTB-style convention): a tracker exact on the other frames scores as a perfect one."""
    truth = [(10, 10, 20, 20), NAN_BOX, (0, 0, 0, 0), (10, 10, 20, 20)]
    predicted = [(10, 10, 20, 20)] * 4
    assert precision_at(predicted, truth) == 1.0  # was 0.5
    assert success_auc(predicted, truth) == pytest.approx(20 / 21)  # was 10 / 21
    far = [(10, 10, 20, 20), (10, 10, 20, 20), (10, 10, 20, 20), (200, 200, 20, 20)]
    assert precision_at(far, truth) == 0.5 and success_curve(far, truth)[0] == 0.5


def test_no_frame_with_ground_truth_is_an_error():
    with pytest.raises(ValueError, match="no frame has a ground-truth box"):
        success_auc([(0, 0, 1, 1)], [(0, 0, 0, 0)])


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


def _sequence_on_disk(folder, frames: int, boxes=None) -> Sequence:
    folder.mkdir(exist_ok=True)
    seq = render_sequence(frames=frames, seed=0)
    paths = tuple(folder / f"{i}.png" for i in range(frames))
    for path, frame in zip(paths, seq.frames):
        cv2.imwrite(str(path), frame)
    return Sequence("synthetic", frame_paths=paths, groundtruth=tuple(boxes or seq.boxes))


class _Still:
    def init(self, frame, box, timestamp):
        self.box = box

    def update(self, frame, timestamp):
        return TargetEstimate(self.box, (0.0, 0.0), 1.0, TrackState.TRACKING, timestamp, 0)


@pytest.mark.parametrize("first", [NAN_BOX, (0.0, 0.0, 0.0, 0.0), (10.0, 10.0, 0.0, 5.0)])
def test_run_sequence_refuses_a_missing_or_empty_first_box(tmp_path, first):
    sequence = _sequence_on_disk(tmp_path, 2, [first, (10.0, 10.0, 20.0, 20.0)])
    with pytest.raises(ValueError, match="synthetic: the first ground-truth box .* is missing or empty"):
        run_sequence(_Still(), sequence)  # NaN: once a ValueError deep in the tracker; 0,0,0,0: once scored


def test_fps_of_a_one_frame_sequence_is_none_in_the_json_rows(tmp_path):
    result = run_sequence(_Still(), _sequence_on_disk(tmp_path, 1))
    assert math.isnan(result.fps) and math.isnan(result.cpu_fps)  # nothing was timed; once infinite
    assert result.as_dict()["fps"] is None
    summary = summarize([result])
    assert summary["fps"] is None and summary["cpu_fps"] is None
    json.dumps([result.as_dict(), summary], allow_nan=False)  # strict JSON: no Infinity, no NaN


def test_summary_fps_is_the_median_of_the_measured_sequences(tmp_path):
    one = run_sequence(_Still(), _sequence_on_disk(tmp_path / "one", 1))
    three = run_sequence(_Still(), _sequence_on_disk(tmp_path, 3))
    assert summarize([one, three])["fps"] == round(three.fps, 1) > 0


# IoU of boxes that overlap along one axis only.
@pytest.mark.parametrize("other", [(2.0, 30.0, 10.0, 10.0), (30.0, 2.0, 10.0, 10.0), (-30.0, -2.0, 10.0, 10.0)])
def test_boxes_apart_on_one_axis_do_not_overlap(other: tuple[float, float, float, float]) -> None:
    """Side by side (or one above the other) with a shared span on the other axis: IoU is 0, not
    the negative ratio a negative intersection height or width times a positive one would give."""
    assert iou((0.0, 0.0, 10.0, 10.0), other) == 0.0
    assert iou(other, (0.0, 0.0, 10.0, 10.0)) == 0.0


# Boxes as N x 4 numpy arrays score the same as lists of tuples (an array's truth value was an
# ambiguous-truth-value error from numpy).
NAN = float("nan")
TRUTH = [(0.0, 0.0, 10.0, 10.0), (NAN, NAN, NAN, NAN), (5.0, 5.0, 10.0, 10.0), (40.0, 0.0, 10.0, 10.0)]
PREDICTED = [(0.0, 0.0, 10.0, 10.0), (0.0, 0.0, 10.0, 10.0), (8.0, 5.0, 10.0, 10.0), (0.0, 0.0, 10.0, 10.0)]


@pytest.mark.parametrize("score", [precision_at, success_auc])
def test_arrays_score_as_lists(score) -> None:
    assert score(np.array(PREDICTED), np.array(TRUTH)) == score(PREDICTED, TRUTH)


@pytest.mark.parametrize("measure", [center_errors, overlaps])
def test_arrays_measure_as_lists(measure) -> None:
    np.testing.assert_array_equal(measure(np.array(PREDICTED), np.array(TRUTH)), measure(PREDICTED, TRUTH))


def test_empty_arrays_are_refused_by_name() -> None:
    with pytest.raises(ValueError, match="non-zero box counts"):
        success_auc(np.zeros((0, 4)), np.zeros((0, 4)))


# Which boxes count as ground truth, and per-frame figures of mismatched box lists.
@pytest.mark.parametrize("box", [(3.0, 4.0, 10.0, 0.0), (3.0, 4.0, 0.0, 0.0), (3.0, 4.0, -1.0, 10.0)])
def test_a_box_without_height_or_width_is_no_ground_truth(box: tuple[float, float, float, float]) -> None:
    assert not has_truth(box)


@pytest.mark.parametrize("figure", [center_errors, overlaps])
def test_per_frame_figures_refuse_lists_of_different_lengths(figure: Callable[..., np.ndarray]) -> None:
    """``zip`` would quietly drop the unmatched frames."""
    with pytest.raises(ValueError, match="equal"):
        figure([(0, 0, 10, 10)] * 3, [(0, 0, 10, 10)] * 2)
    with pytest.raises(ValueError, match="equal"):
        figure([(0, 0, 10, 10)], [(0, 0, 10, 10)] * 2)


# The overall row of an evaluation: scores are means over the sequences.
def test_precision_and_auc_are_means_not_medians() -> None:
    results = [SequenceResult(f"s{i}", 10, prec, auc, 30.0, []) for i, (prec, auc) in
               enumerate([(0.1, 0.05), (0.2, 0.1), (0.9, 0.75)])]
    summary = summarize(results)
    assert summary["sequences"] == 3
    assert summary["prec20"] == pytest.approx(0.4) and summary["auc"] == pytest.approx(0.3)
