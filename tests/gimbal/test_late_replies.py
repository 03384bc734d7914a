"""Issue #26 item 5: replies that arrive after their command was given up on (``sim --delay-ms 150``)
are counted as late and dropped; they never answer a newer command, and nobody blames another host."""
from __future__ import annotations

import itertools
import logging

import pytest

from gimbal.client import GimbalClient
from gimbal.errors import BusError, GimbalTimeoutError
from gimbal.messages.motion import AnglesReply, GetAngles, SpeedControl
from tests.gimbal.scripted_peer import ScriptedPeer, poll

DELAY_S = 0.15  # every reply, as with `gimbaltrack sim --delay-ms 150`


def test_a_late_reply_never_answers_a_newer_request(channel: str, peer: ScriptedPeer,
                                                    caplog: pytest.LogCaptureFixture) -> None:
    numbers = itertools.count(1)
    peer.answer(GetAngles, lambda request: AnglesReply(0, 1, next(numbers), 0, 0), delay=DELAY_S)
    with caplog.at_level(logging.WARNING), \
            GimbalClient(interface="virtual", channel=channel, timeout=0.1, retries=0) as client:
        for _ in range(3):
            with pytest.raises(GimbalTimeoutError):
                client.request(GetAngles())
        poll(lambda: client.stats["late_replies"] == 3)
        assert client.stats["misattributed_replies"] == 0
        peer.answer(GetAngles, AnglesReply(0, 1, 42, 0, 0))  # on time again
        assert client.request(GetAngles()).yaw == 42
    assert "another host" not in caplog.text


def test_a_slow_gimbal_under_the_keep_alive_gets_no_reply_paired_with_a_newer_command(
        channel: str, peer: ScriptedPeer, caplog: pytest.LogCaptureFixture) -> None:
    peer.answer(SpeedControl, delay=DELAY_S)
    with caplog.at_level(logging.WARNING), GimbalClient(interface="virtual", channel=channel) as client:
        streamer = client.speed_streamer(rate_hz=25.0, max_age=60.0)
        streamer.set(10.0, 0.0)
        poll(lambda: streamer.error is not None)  # every reply missed its send's window
        with pytest.raises(BusError):
            streamer.set(10.0, 0.0)
        streamer.stop()
        poll(lambda: client.stats["late_replies"] >= streamer.max_missed_replies)
        assert streamer.stats["replies"] == 0
        assert streamer.stats["reply_timeouts"] == streamer.max_missed_replies
        assert client.stats["misattributed_replies"] == 0
    assert "another host" not in caplog.text
