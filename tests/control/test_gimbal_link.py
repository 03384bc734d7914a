"""GimbalLink: control's one view of the gimbal (pushes in degrees, signs, setpoints out)."""
import math

import pytest

from gimbal.messages.telemetry import ParameterPush
from pipelines.control.controller import RateCommand
from pipelines.control.gimbal_link import GimbalLink, Signs


class Client:
    """What GimbalLink uses of a GimbalClient, recorded."""

    def __init__(self):
        self.calls = []
        self.stats = {"stop_sent": 1, "pushes": 9}

    def on_push(self, cls, callback):
        self.calls.append(("on_push", cls, callback))
        return lambda: None

    def set_push(self, enabled):
        self.calls.append(("set_push", enabled))

    def wait_for_push(self, cls, timeout):
        self.calls.append(("wait_for_push", cls, timeout))

    def speed_streamer(self, rate_hz, bus_timeout):
        self.calls.append(("speed_streamer", rate_hz))
        return Streamer(self.calls)


class Streamer:
    def __init__(self, calls):
        self.calls = calls
        self.stats = {"sent": 3}

    def set(self, yaw, pitch, stamp=None):
        self.calls.append(("set", yaw, pitch, stamp))

    def stop(self):
        self.calls.append(("stop",))

    def latencies(self):
        return [0.01]


def test_push_callback_reads_degrees_and_skips_invalid_angles():
    link = GimbalLink(Client())
    link.on_push(ParameterPush(ctrl_byte=0, yaw_angle=10, roll_angle=0, pitch_angle=0), 1.0)
    link.on_push(ParameterPush(ctrl_byte=1), 1.5)  # flag set but a push too short for angles
    assert link.latest() is None
    link.on_push(ParameterPush(ctrl_byte=1, yaw_angle=-1795, roll_angle=3, pitch_angle=-120), 2.0)
    a = link.latest()
    assert (a.yaw, a.roll, a.pitch, a.timestamp) == pytest.approx((-179.5, 0.3, -12.0, 2.0))


def test_start_subscribes_enables_the_push_then_streams():
    client = Client()
    link = GimbalLink(client, rate_hz=40.0)
    assert not link.started and link.latencies() == []
    link.start(wait_s=1.0)
    assert client.calls == [("on_push", ParameterPush, link.on_push), ("set_push", True),
                            ("wait_for_push", ParameterPush, 1.0), ("speed_streamer", 40.0)]
    assert link.started and link.stats() == {"sent": 3, "stop_sent": 1}


def test_signs_of_speed_and_attitude_are_separate():
    """One RS 5 turns the other way for a positive yaw speed and still reports its yaw the usual way."""
    client = Client()
    link = GimbalLink(client, signs=Signs(yaw_speed=-1, pitch_attitude=-1))
    link.start()
    link.send(RateCommand(10.0, 5.0), stamp=3.0)
    assert client.calls[-1] == ("set", -10.0, 5.0, 3.0)
    link.history.add(1.0, 10.0, 0.0, 5.0)
    assert link.attitude_at(1.0) == (10.0, -5.0)
    assert (link.latest().yaw, link.latest().pitch) == (10.0, 5.0)  # as reported, for the telemetry
    link.stop()
    assert client.calls[-1] == ("stop",)


def test_before_start_nothing_is_sent_and_a_stop_is_harmless():
    link = GimbalLink(Client())
    with pytest.raises(RuntimeError, match="before start"):
        link.send(RateCommand(1.0, 1.0))
    link.stop()
    assert link.attitude_at(0.0) is None and not math.isnan(link.rate_hz)


@pytest.mark.parametrize("value", [0, 2, -2, True + 1])
def test_signs_are_plus_or_minus_one(value):
    with pytest.raises(ValueError, match="must be 1 or -1"):
        Signs(yaw_speed=value)
