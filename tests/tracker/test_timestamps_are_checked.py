"""A frame's timestamp is the Kalman filter's clock: None, NaN or a string is refused by name (None
was a bare TypeError from ``update``; ``init`` took both)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from tracker import make_tracker
from tracker.evaluation.synthetic import render_sequence


@pytest.mark.parametrize("timestamp", [None, math.nan, math.inf, "0.1", True])
def test_a_timestamp_that_is_not_a_finite_number_is_refused(timestamp: object) -> None:
    seq = render_sequence(frames=2, seed=1)
    tracker = make_tracker("dcf")
    with pytest.raises(ValueError, match="timestamp must be a finite number of seconds"):
        tracker.init(seq.frames[0], seq.boxes[0], timestamp)  # type: ignore[arg-type]
    tracker.init(seq.frames[0], seq.boxes[0], np.float64(0.0))
    with pytest.raises(ValueError, match="timestamp must be a finite number of seconds"):
        tracker.update(seq.frames[1], timestamp)  # type: ignore[arg-type]
    assert all(math.isfinite(v) for v in tracker.update(seq.frames[1], 1 / 30).box)
