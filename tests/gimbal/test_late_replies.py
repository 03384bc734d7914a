"""Issue #26 item 5: replies that arrive after their command was given up on (``sim --delay-ms 150``)
are counted as late and dropped; they never answer a newer command, and nobody blames another host."""
from __future__ import annotations

import itertools
import logging

import pytest

from gimbal.client import GimbalClient
from gimbal.errors import GimbalTimeoutError
from gimbal.messages.motion import AnglesReply, GetAngles, SpeedControl
from gimbal.watchdog import DISENGAGED, ENGAGED
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
    """At 25 Hz every reply misses its command's 40 ms window: each is late, none is taken for
    a newer command's, and the late ones show the gimbal hears us, so streaming goes on."""
    peer.answer(SpeedControl, delay=DELAY_S)
    with caplog.at_level(logging.WARNING), GimbalClient(interface="virtual", channel=channel) as client:
        streamer = client.speed_streamer(rate_hz=25.0, max_age=60.0)
        streamer.set(10.0, 0.0)
        poll(lambda: streamer.stats["late_replies"] >= 20)
        assert streamer.error is None and streamer.running
        health = streamer.watchdog.snapshot()
        assert (health.state, health.unanswered, health.episodes) == (ENGAGED, 0, 0)
        streamer.stop()
        assert streamer.stats["replies"] == 0
        assert client.stats["late_replies"] >= streamer.stats["late_replies"]
        assert client.stats["misattributed_replies"] == 0
    assert "another host" not in caplog.text


def test_a_gimbal_that_goes_silent_after_answering_late_is_released(channel: str, peer: ScriptedPeer) -> None:
    peer.answer(SpeedControl, delay=DELAY_S)
    with GimbalClient(interface="virtual", channel=channel) as client:
        streamer = client.speed_streamer(rate_hz=25.0, max_age=60.0, bus_timeout=0.6)
        streamer.set(10.0, 0.0)
        poll(lambda: streamer.stats["late_replies"] >= 3)
        peer.silence(SpeedControl)
        poll(lambda: streamer.watchdog.poll() == DISENGAGED)
        poll(lambda: streamer.stats["probes"] >= 1)
        assert streamer.stats["unanswered"] >= 10 and streamer.error is None
