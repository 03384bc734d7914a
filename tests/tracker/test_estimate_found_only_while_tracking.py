"""``TargetEstimate.found``: the subject is in hand only while it is tracked."""
import pytest

from tracker.runtime.estimate import TargetEstimate, TrackState


@pytest.mark.parametrize("state", list(TrackState))
def test_found_is_true_for_tracking_only(state: TrackState) -> None:
    estimate = TargetEstimate((10.0, 20.0, 30.0, 40.0), (0.0, 0.0), 0.5, state, 1.0, 3)
    assert estimate.found is (state is TrackState.TRACKING)
    assert estimate.center == (25.0, 40.0)
