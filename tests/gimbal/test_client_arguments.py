"""What GimbalClient's arguments take: each is checked where it is given, by name, and numpy's
numbers and bools count as Python's."""
from __future__ import annotations

import json
import math
from collections.abc import Iterator

import can
import numpy as np
import pytest

from gimbal.client import (
    GimbalClient, ORIENTATIONS, SPEED_HOLD, SPEED_RELEASE, position_message, speed_message,
)
from gimbal.errors import RangeError
from gimbal.messages.motion import GetAngles, SpeedControl
from gimbal.messages.settings import SetWorkMode
from gimbal.messages.telemetry import PUSH_DISABLE, PUSH_ENABLE, ParameterPush, PushControl
from gimbal.sim import start_in_process
from tests.gimbal.scripted_peer import ScriptedPeer


# Timeouts, retry counts and push callbacks are checked where they are given, by name: a
# ``retries=1.5``, a numpy timeout, a per-request NaN or negative timeout, a push wait of ``None``
# and a callback of ``None`` were taken and failed later (a TypeError on the first request, retries
# "within nan ms", a traceback logged on the receive thread for every push).
@pytest.fixture
def bus(channel: str) -> Iterator[can.BusABC]:
    bus = can.Bus(interface="virtual", channel=channel)
    yield bus
    bus.shutdown()


@pytest.mark.parametrize("retries", [1.5, -1, True, None, "2"])
def test_a_retry_count_that_is_no_whole_number_is_refused(bus: can.BusABC, retries: object) -> None:
    with pytest.raises(ValueError, match="retries must be a whole number, 0 or more, not"):
        GimbalClient(bus, retries=retries)  # type: ignore[arg-type]


@pytest.mark.parametrize("timeout", [None, "0.1", True])
def test_a_timeout_that_is_no_number_is_refused(bus: can.BusABC, timeout: object) -> None:
    with pytest.raises(ValueError, match="timeout must be above 0"):
        GimbalClient(bus, timeout=timeout)  # type: ignore[arg-type]


def test_numpy_numbers_are_taken() -> None:
    host_bus, sim = start_in_process()
    try:
        with GimbalClient(host_bus, timeout=np.float32(0.2), retries=np.int64(1)) as client:
            assert (client.timeout, client.retries) == (pytest.approx(0.2), 1)
            assert client.get_angles().kind == "attitude"
    finally:
        sim.stop()
        host_bus.shutdown()


@pytest.mark.parametrize("timeout", [math.nan, -1.0, 0.0])
def test_a_per_request_timeout_is_checked(bus: can.BusABC, timeout: float) -> None:
    with GimbalClient(bus) as client:
        with pytest.raises(ValueError, match="timeout must be above 0"):
            client.request(GetAngles(1), timeout=timeout)


@pytest.mark.parametrize("timeout", [None, math.nan, -1.0])
def test_a_push_wait_timeout_is_checked(bus: can.BusABC, timeout: object) -> None:
    with GimbalClient(bus) as client:
        with pytest.raises(ValueError, match="a push timeout must be 0 to"):
            client.wait_for_push(ParameterPush, timeout)  # type: ignore[arg-type]


def test_a_callback_that_cannot_be_called_is_refused(bus: can.BusABC) -> None:
    with GimbalClient(bus) as client:
        with pytest.raises(TypeError, match="a push callback must be callable, not None"):
            client.on_push(ParameterPush, None)  # type: ignore[arg-type]


# Angles and speeds computed with numpy (float32, int64) go out like Python numbers; a speed
# setpoint's stamp that is not a finite number is refused by ``set()``, not later by the streaming
# thread (which stopped streaming with a TypeError).
@pytest.fixture
def client(channel: str, peer: ScriptedPeer) -> Iterator[GimbalClient]:
    peer.answer(SpeedControl)
    with GimbalClient(interface="virtual", channel=channel, timeout=0.2, retries=1) as gimbal:
        yield gimbal


@pytest.mark.parametrize("value", [np.float32(12.5), np.float64(12.5), np.int64(12), np.int32(12)])
def test_numpy_numbers_make_the_same_messages(value) -> None:
    plain = float(value)
    assert position_message(yaw=value, pitch=value, time_s=value) == position_message(yaw=plain, pitch=plain,
                                                                                       time_s=plain)
    assert speed_message(value, -value) == speed_message(plain, -plain)


@pytest.mark.parametrize("value, said", [(None, "not a number"), ("5", "not a number"), (True, "not a number"),
                                         (np.float32("nan"), "not a finite number")])
def test_what_is_not_a_finite_number_is_named(value, said: str) -> None:
    with pytest.raises(RangeError, match=f"yaw angle=.* is {said}$"):
        position_message(yaw=value)


def test_the_streamer_takes_numpy_speeds(client: GimbalClient, peer: ScriptedPeer) -> None:
    streamer = client.speed_streamer()
    streamer.set(np.float32(2.5), np.int64(-3), stamp=np.float64(0.0))
    peer.wait_for(SpeedControl, where=lambda m: m.yaw_speed == 25 and m.pitch_speed == -30)


@pytest.mark.parametrize("stamp", ["now", float("nan"), float("inf")])
def test_a_bad_stamp_is_refused_and_streaming_goes_on(client: GimbalClient, peer: ScriptedPeer, stamp) -> None:
    streamer = client.speed_streamer()
    with pytest.raises(RangeError, match="stamp="):
        streamer.set(1.0, 0.0, stamp=stamp)
    streamer.set(2.0, 0.0)
    peer.wait_for(SpeedControl, where=lambda m: m.yaw_speed == 20)
    assert streamer.running and streamer.error is None


def test_numpy_integers_make_the_same_commands(channel: str, peer: ScriptedPeer) -> None:
    """Integer fields and raw choices computed with numpy: once "must be an integer, not
    np.int64(1)" from the codec, or "orientation np.int64(1) is not one of ..." from the client."""
    message = PushControl(np.int64(PUSH_ENABLE))
    assert message.encode_payload() == PushControl(PUSH_ENABLE).encode_payload()
    assert json.dumps(message.fields()) == json.dumps(PushControl(PUSH_ENABLE).fields())
    peer.answer(SetWorkMode)
    with GimbalClient(interface="virtual", channel=channel, timeout=0.2, retries=0) as client:
        client.set_work_mode(np.int64(ORIENTATIONS["portrait"]))
    assert [m.orientation for m in peer.messages(SetWorkMode)] == [ORIENTATIONS["portrait"]]


# On/off arguments take True or False (numpy's too), not any value Python would call true: the
# string "no" turned the parameter push on and took speed control.
@pytest.mark.parametrize("value", ["no", "", None, 1, 0.0])
def test_anything_but_a_bool_is_refused_before_sending(value: object, channel: str, peer: ScriptedPeer) -> None:
    peer.answer(PushControl)
    with GimbalClient(interface="virtual", channel=channel, timeout=0.2, retries=0) as client:
        with pytest.raises(TypeError, match=r"^enabled must be True or False, not "):
            client.set_push(value)  # type: ignore[arg-type]
        with pytest.raises(TypeError, match=r"^start must be True or False, not "):
            client.auto_calibration(value)  # type: ignore[arg-type]
    assert peer.messages(PushControl) == []
    with pytest.raises(TypeError, match=r"^take_control must be True or False, not "):
        speed_message(1.0, 0.0, take_control=value)  # type: ignore[arg-type]


def test_numpy_bools_are_taken(channel: str, peer: ScriptedPeer) -> None:
    peer.answer(PushControl)
    with GimbalClient(interface="virtual", channel=channel, timeout=0.2, retries=0) as client:
        client.set_push(np.bool_(False))
    assert [m.ctrl_byte for m in peer.messages(PushControl)] == [PUSH_DISABLE]
    assert speed_message(1.0, 0.0, take_control=np.bool_(True)).ctrl_byte == SPEED_HOLD
    assert speed_message(1.0, 0.0, take_control=np.bool_(False)).ctrl_byte == SPEED_RELEASE
