"""Angles and speeds computed with numpy (float32, int64) go out like Python numbers; a speed
setpoint's stamp that is not a finite number is refused by ``set()``, not later by the streaming
thread (which stopped streaming with a TypeError)."""
from __future__ import annotations

import json
from collections.abc import Iterator

import numpy as np
import pytest

from gimbal.client import ORIENTATIONS, GimbalClient, position_message, speed_message
from gimbal.errors import RangeError
from gimbal.messages.motion import SpeedControl
from gimbal.messages.settings import SetWorkMode
from gimbal.messages.telemetry import PUSH_ENABLE, PushControl
from tests.gimbal.scripted_peer import ScriptedPeer


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
