import pytest

from pipelines.control.attitude import AttitudeHistory


def test_interpolation():
    h = AttitudeHistory()
    assert h.at(1.0) is None
    h.add(1.0, 10.0, -2.0, 5.0)
    h.add(2.0, 30.0, 0.0, -5.0)
    a = h.at(1.25)
    assert (a.yaw, a.roll, a.pitch) == pytest.approx((15.0, -1.5, 2.5))
    assert h.at(0.0).yaw == pytest.approx(10.0)  # before the first sample: the first


def test_yaw_interpolates_through_the_wrap():
    h = AttitudeHistory()
    h.add(0.0, 178.0, 0.0, 0.0)
    h.add(1.0, -178.0, 0.0, 0.0)
    assert abs(h.at(0.5).yaw) == pytest.approx(180.0)
    assert h.at(0.25).yaw == pytest.approx(179.0)
    assert h.at(0.75).yaw == pytest.approx(-179.0)


def test_extrapolation_is_capped_then_held():
    h = AttitudeHistory(max_extrapolation=0.1)
    h.add(0.0, 0.0, 0.0, 0.0)
    h.add(0.1, 1.0, 0.0, 0.0)  # 10 deg/s
    assert h.at(0.15).yaw == pytest.approx(1.5)
    assert h.at(5.0).yaw == pytest.approx(2.0)


def test_bounded_and_ordered():
    h = AttitudeHistory(maxlen=4)
    for i in range(10):
        h.add(float(i), float(i), 0.0, 0.0)
    h.add(3.0, 99.0, 0.0, 0.0)  # out of order: ignored
    assert len(h) == 4
    assert h.latest().yaw == 9.0


# ``AttitudeHistory.at`` inside a history of several samples and exactly at the newest one.
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
