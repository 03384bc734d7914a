"""``box_response`` works on each feature cell's mean likelihood, not on one sampled pixel of it."""
from __future__ import annotations

import numpy as np

from tracker.backends.colour_model import box_response


def test_a_half_covered_cell_counts_one_half() -> None:
    likelihood = np.zeros((8, 8), np.float32)
    likelihood[0:4, 0:2] = 1.0  # the left half of the top-left 4 x 4 cell
    np.testing.assert_allclose(box_response(likelihood, 4, (1, 1)), [[0.5, 0.0], [0.0, 0.0]])
