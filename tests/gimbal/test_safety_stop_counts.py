"""The safety stop's two speed commands (zero in control, then zero with bit 7 clear: section
2.3.4.2, Figure 8) are counted apart in ``GimbalClient.stats``."""
from __future__ import annotations

import time

import pytest

from gimbal.client import GimbalClient
from gimbal.errors import GimbalTimeoutError, ReturnCodeError
from gimbal.messages.motion import SpeedControl, SpeedControlReply
from gimbal.session import STOP_RETRY_S
from tests.gimbal.scripted_peer import RELEASE, ZERO, ScriptedPeer, speed_messages


def test_the_zero_and_the_release_are_counted_each_once(channel: str, peer: ScriptedPeer) -> None:
    peer.answer(SpeedControl)
    with GimbalClient(interface="virtual", channel=channel, timeout=0.2, retries=0) as client:
        client.speed(10, 0)
    assert speed_messages(peer)[-2:] == [ZERO, RELEASE]
    assert (client.stats["stop_zero_sent"], client.stats["stop_release_sent"]) == (1, 1)


def test_a_stop_the_gimbal_leaves_unanswered_is_still_counted_as_sent(channel: str, peer: ScriptedPeer) -> None:
    """A gimbal gone silent: the two stops go out (each resent until its time is up, issue #26
    item 4) and are in the CAN log, so the counts say they were sent, not nothing."""
    peer.silence(SpeedControl)
    with GimbalClient(interface="virtual", channel=channel, timeout=0.05, retries=0) as client:
        with pytest.raises(GimbalTimeoutError):
            client.speed(10, 0)
    stop = speed_messages(peer)[1:]  # after the speed command itself
    zeros = stop.index(RELEASE)
    assert stop[:zeros] == [ZERO] * zeros and stop[zeros:] == [RELEASE] * (len(stop) - zeros)
    assert zeros >= 2 and len(stop) - zeros >= 2
    assert (client.stats["stop_zero_sent"], client.stats["stop_release_sent"]) == (1, 1)
    assert client.stats["stop_resends"] == len(stop) - 2


def test_a_stop_the_gimbal_refuses_is_still_counted_as_sent(channel: str, peer: ScriptedPeer) -> None:
    peer.nack(SpeedControl, 0x02)
    with GimbalClient(interface="virtual", channel=channel, timeout=0.2, retries=0) as client:
        with pytest.raises(ReturnCodeError):
            client.speed(10, 0)
    assert speed_messages(peer)[-2:] == [ZERO, RELEASE]
    assert (client.stats["stop_zero_sent"], client.stats["stop_release_sent"]) == (1, 1)


def test_the_final_stop_is_resent_until_answered(channel: str, peer: ScriptedPeer) -> None:
    """Issue #26 item 4: under `sim --corrupt 0.1` a SIGTERM's zero and release went unanswered
    and were never sent again. Here the first two zeros and the first release get no reply."""
    unanswered = {ZERO: 2, RELEASE: 1}

    def flaky(request: SpeedControl) -> SpeedControlReply | None:
        key = (request.yaw_speed, request.roll_speed, request.pitch_speed, request.ctrl_byte)
        if unanswered.get(key, 0) > 0:
            unanswered[key] -= 1
            return None
        return SpeedControlReply()

    peer.answer(SpeedControl, flaky)
    with GimbalClient(interface="virtual", channel=channel, timeout=0.2, retries=0) as client:
        client.speed(10, 0)
        started = time.monotonic()
        client.stop_and_release()
        took = time.monotonic() - started
    assert speed_messages(peer)[1:] == [ZERO, ZERO, ZERO, RELEASE, RELEASE]
    assert client.stats["stop_resends"] == 3
    assert took < STOP_RETRY_S
