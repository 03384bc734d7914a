"""The direction filter's measurement noise is a variance of ``measurement_std_deg`` squared."""
import pytest

from pipelines.control.direction import DirectionFilter


@pytest.mark.parametrize("std", [0.15, 2.0])
def test_a_second_measurement_at_the_same_instant_is_averaged_with_the_first(std: float) -> None:
    """The start takes the first measurement with its noise (variance std**2); a second one at the
    same time, as noisy, carries equal weight: the estimate lands half way."""
    kf = DirectionFilter(measurement_std_deg=std)
    kf.update((10.0, -4.0), 1.0)
    d = kf.update((11.0, -3.0), 1.0)
    assert (d.yaw, d.pitch) == pytest.approx((10.5, -3.5))
    assert d.timestamp == 1.0


def test_an_older_measurement_does_not_take_the_state_back_in_time() -> None:
    kf = DirectionFilter()
    kf.update((10.0, 0.0), 1.0)
    assert kf.update((10.0, 0.0), 0.5).timestamp == 1.0
