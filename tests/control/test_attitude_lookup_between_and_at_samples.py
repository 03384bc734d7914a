"""``AttitudeHistory.at`` inside a history of several samples and exactly at the newest one."""
import pytest

from pipelines.control.attitude import AttitudeHistory


def _accelerating() -> AttitudeHistory:
    """Yaw 0, 10, 30, 60 deg at t = 0, 1, 2, 3 s: each span at its own rate."""
    history = AttitudeHistory()
    for t, yaw in enumerate((0.0, 10.0, 30.0, 60.0)):
        history.add(float(t), yaw, 0.0, -yaw / 10.0)
    return history


def test_a_time_between_older_samples_interpolates_its_own_span() -> None:
    attitude = _accelerating().at(1.5)
    assert (attitude.yaw, attitude.pitch, attitude.timestamp) == pytest.approx((20.0, -2.0, 1.5))


def test_the_newest_samples_time_gives_the_newest_sample() -> None:
    history = _accelerating()
    assert (history.at(3.0).yaw, history.at(3.0).pitch) == pytest.approx((60.0, -6.0))
    assert history.at(3.05).yaw == pytest.approx(61.5)  # extrapolated at the last span's 30 deg/s
