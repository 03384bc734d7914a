"""Boxes as N x 4 numpy arrays score the same as lists of tuples (an array's truth value was an
ambiguous-truth-value error from numpy)."""
from __future__ import annotations

import numpy as np
import pytest

from tracker.evaluation.metrics import center_errors, overlaps, precision_at, success_auc

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
