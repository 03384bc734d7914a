"""The overall row of an evaluation: scores are means over the sequences."""
import pytest

from tracker.evaluation import SequenceResult, summarize


def test_precision_and_auc_are_means_not_medians() -> None:
    results = [SequenceResult(f"s{i}", 10, prec, auc, 30.0, []) for i, (prec, auc) in
               enumerate([(0.1, 0.05), (0.2, 0.1), (0.9, 0.75)])]
    summary = summarize(results)
    assert summary["sequences"] == 3
    assert summary["prec20"] == pytest.approx(0.4) and summary["auc"] == pytest.approx(0.3)
