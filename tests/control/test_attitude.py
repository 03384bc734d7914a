import pytest

from gimbal.messages.telemetry import ParameterPush
from pipelines.control.attitude import AttitudeHistory


def test_raw_units_and_interpolation():
    h = AttitudeHistory()
    assert h.at(1.0) is None
    h.on_push(ParameterPush(ctrl_byte=1, yaw_angle=100, roll_angle=-20, pitch_angle=50), 1.0)  # 10.0, -2.0, 5.0 deg
    h.on_push(ParameterPush(ctrl_byte=1, yaw_angle=300, roll_angle=0, pitch_angle=-50), 2.0)
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


def test_push_callback_reads_raw_fields_and_skips_invalid_angles():
    h = AttitudeHistory()
    h.on_push(ParameterPush(ctrl_byte=0, yaw_angle=10, roll_angle=0, pitch_angle=0), 1.0)
    h.on_push(ParameterPush(ctrl_byte=1), 1.5)  # flag set but a push too short for angles
    assert len(h) == 0
    h.on_push(ParameterPush(ctrl_byte=1, yaw_angle=-1795, roll_angle=3, pitch_angle=-120), 2.0)
    a = h.latest()
    assert (a.yaw, a.roll, a.pitch, a.timestamp) == pytest.approx((-179.5, 0.3, -12.0, 2.0))


def test_attach_subscribes_to_the_attitude_push_and_enables_it():
    calls = []

    class Client:
        def on_push(self, cls, callback):
            calls.append(("on_push", cls, callback))
            return lambda: calls.append(("unsubscribe",))

        def set_push(self, enabled):
            calls.append(("set_push", enabled))

    h = AttitudeHistory()
    unsubscribe = h.attach(Client())
    assert calls == [("on_push", ParameterPush, h.on_push), ("set_push", True)]
    unsubscribe()
    assert calls[-1] == ("unsubscribe",)
