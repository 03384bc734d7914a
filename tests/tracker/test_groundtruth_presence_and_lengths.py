"""Which boxes count as ground truth, and per-frame figures of mismatched box lists."""
from collections.abc import Callable

import numpy as np
import pytest

from tracker.evaluation.metrics import center_errors, has_truth, overlaps


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
